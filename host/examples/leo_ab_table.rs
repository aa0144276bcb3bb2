//! The A/B table of `sim/src/leo/README.md`: the largest angle error
//! (rad, torso and the seven joints) over the first 0.2 s, or until the
//! framework's first touchdown if that comes sooner, of pada's LEO driven
//! open loop by each reference of `tests/data/leo-ab/` (every servo's
//! applied voltage), at each number of physics steps per control period.
//!
//! cargo run --release -p pada --example leo_ab_table [-- 2 4 8 12 48]
use pada::leo::compare::{compare, references_in, Drive};
use pada::leo::model::ModelOptions;

/// 0.2 s of control steps: the horizon of the step-size study.
const HORIZON_STEPS: usize = 6;

fn main() {
    let substeps: Vec<u32> = {
        let args: Vec<u32> = std::env::args()
            .skip(1)
            .map(|a| a.parse().expect("physics steps per control period, e.g. 4"))
            .collect();
        if args.is_empty() {
            vec![2, 4, 8, 12, 48]
        } else {
            args
        }
    };
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/leo-ab");
    let references = references_in(std::path::Path::new(dir)).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(1);
    });
    print!("| reference |");
    for s in &substeps {
        print!(" {s} steps |");
    }
    println!();
    print!("|---|");
    for _ in &substeps {
        print!("---|");
    }
    println!();
    let mut worst = vec![0.0f32; substeps.len()];
    for (name, reference) in references {
        print!("| `{name}` |");
        for (i, &s) in substeps.iter().enumerate() {
            let options = ModelOptions {
                substeps: s,
                ..ModelOptions::default()
            };
            let c = compare(&reference, Drive::Applied, options).expect("the model builds");
            let n = HORIZON_STEPS.min(c.first_touchdown.unwrap_or(usize::MAX));
            let e = c
                .steps
                .iter()
                .take(n)
                .flat_map(|s| s.angle_error)
                .fold(0.0f32, |m, e| m.max(e.abs()));
            worst[i] = worst[i].max(e);
            print!(" {e:.4} |");
        }
        println!();
    }
    print!("| **largest** |");
    for w in worst {
        print!(" **{w:.4}** |");
    }
    println!();
}
