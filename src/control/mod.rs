//! What drives the arm: the tutorial's PD + gravity feed-forward controller (or a torque law of the
//! user's, `law`), its gains (the
//! tutorial's, or auto-tuned for any arm), the commanded trajectories, and the inverse kinematics
//! that turns a drawn shape into a joint schedule; the sampled loop's linearization and stability
//! (`sampled_loop`), which auto-tuning and `armscope analyze` both use.

pub mod controller;
pub mod demand;
pub mod gains;
pub mod ik;
pub mod law;
pub mod sampled_loop;
pub mod trajectory;
pub mod within_effort;
