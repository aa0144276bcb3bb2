//! pada-core's capacities, each defined once and derived from the others
//! where they are the same limit. Every one is the capacity of a heapless
//! type or a fixed-size array, so running out is an error (counted and
//! reported), never a truncation or a panic. A limit that is really another
//! one has its own name, even where the numbers agree.
//!
//! | name | value | what it bounds |
//! |---|---|---|
//! | [`MAX_STATE_DIMS`] | 16 | the tile coder's state dimensions, the observation and the policy's own together; a telemetry `Step`'s state |
//! | [`MAX_ACTION_DIMS`] | 4 | a robot's motor outputs (LEO learns 3); a `Step`'s outputs |
//! | [`MAX_LEVELS`] | 16 | levels of one action dimension (the paper's 7 on LEO) |
//! | [`MAX_SERVOS`] | 8 | servos on one robot's bus (LEO's 7 and one spare): the soft limits, the servo temperatures a `Health` report carries, and the learner-state record's fatigue counters, one per servo |
//! | [`MAX_ROBOT_NAME`] | 32 | bytes of a robot's name in `Hello` and the software-in-the-loop link |
//! | [`MAX_GEARBOXES`] | 4 | gearboxes a robot counts for the paper's MTBF (LEO's hips and knees); a `Step`'s fatigue entries |
//!
//! The learner-state record's room for fatigue counters
//! ([`crate::checkpoint::RECORD_JOINTS`]) is [`MAX_SERVOS`]; its layout
//! checks at compile time that the offsets after it still fit.

/// State dimensions a tile coder takes (observation plus the policy's own).
pub const MAX_STATE_DIMS: usize = 16;
/// Action dimensions (motor outputs) of one robot.
pub const MAX_ACTION_DIMS: usize = 4;
/// Levels per action dimension.
pub const MAX_LEVELS: usize = 16;
/// Servos on one robot's bus (LEO has seven).
pub const MAX_SERVOS: usize = 8;
/// Bytes of a robot's name (`crate::robot::RobotSpec::name`), as the
/// wire's `Hello` and the software-in-the-loop link carry it.
pub const MAX_ROBOT_NAME: usize = 32;
/// Gearboxes whose wear a robot counts (LEO's four: hips and knees).
pub const MAX_GEARBOXES: usize = 4;

// A robot's counted gearboxes are some of its servos.
const _: () = assert!(MAX_GEARBOXES <= MAX_SERVOS);
