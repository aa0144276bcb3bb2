//! Where the coarse step's error comes from: pada's LEO at a coarse step
//! against itself at a fine one (48 physics steps per period), driven open
//! loop by each reference of `tests/data/leo-ab/`, with every model part
//! on and then with one part switched off at both steps. The number is the
//! largest difference of the torso and joint angles (rad) over the first
//! 0.2 s, or until the framework's first touchdown if that comes sooner
//! (the horizon of `leo_ab_table`). A part whose removal shrinks the
//! difference is one the coarse step integrates badly.
//!
//! cargo run --release -p pada --example leo_step_error_sources [-- 4]
use pada::leo::compare::{compare, references_in, Drive};
use pada::leo::model::ModelOptions;

/// 0.2 s of control steps: the horizon of the step-size study.
const HORIZON_STEPS: usize = 6;
/// The fine step the coarse one is measured against.
const FINE_SUBSTEPS: u32 = 48;

fn main() {
    let coarse: u32 = match std::env::args().nth(1).map(|a| a.parse()) {
        None => 4,
        Some(Ok(n)) if (1..FINE_SUBSTEPS).contains(&n) => n,
        Some(_) => {
            eprintln!("error: the argument is the coarse step's physics steps per period, 1..{FINE_SUBSTEPS}");
            std::process::exit(2);
        }
    };
    let all = ModelOptions::default();
    let variants: [(&str, ModelOptions); 5] = [
        ("everything on", all),
        ("no dry friction", ModelOptions { dry_friction: false, ..all }),
        ("no lag correction", ModelOptions { motor_lag_correction: false, ..all }),
        ("no floor contacts", ModelOptions { contacts: false, ..all }),
        ("no joint stops", ModelOptions { joint_stops: false, ..all }),
    ];
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/leo-ab");
    let references = references_in(std::path::Path::new(dir)).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(1);
    });
    println!("{coarse} physics steps per period against {FINE_SUBSTEPS}, largest angle difference (rad):\n");
    print!("| reference |");
    for (name, _) in &variants {
        print!(" {name} |");
    }
    println!();
    println!("|---|{}", "---|".repeat(variants.len()));
    let mut worst = [0.0f32; 5];
    for (name, reference) in references {
        print!("| `{name}` |");
        for (i, (_, options)) in variants.iter().enumerate() {
            let run = |substeps| {
                compare(&reference, Drive::Applied, ModelOptions { substeps, ..*options }).expect("the model builds")
            };
            let (a, b) = (run(coarse), run(FINE_SUBSTEPS));
            // Both runs' errors are against the same reference, so their
            // difference is the coarse run against the fine one.
            let n = HORIZON_STEPS.min(a.first_touchdown.unwrap_or(usize::MAX));
            let d = a
                .steps
                .iter()
                .zip(&b.steps)
                .take(n)
                .flat_map(|(x, y)| x.angle_error.iter().zip(&y.angle_error).map(|(p, q)| (p - q).abs()))
                .fold(0.0f32, f32::max);
            worst[i] = worst[i].max(d);
            print!(" {d:.4} |");
        }
        println!();
    }
    print!("| **largest** |");
    for w in worst {
        print!(" **{w:.4}** |");
    }
    println!();
}
