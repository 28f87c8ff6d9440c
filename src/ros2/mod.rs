//! ROS 2's wire format, written once for every part of armscope that speaks it (the ROS 2
//! encoding of the MCAP recordings, the replay of ROS 2 bags): CDR ([`cdr`]), the messages
//! ([`messages`], and the commands of a trajectory controller: [`trajectory`]), their definitions
//! as an MCAP schema carries them ([`definitions`]), and the QoS a channel was offered with
//! ([`qos`]).

pub mod cdr;
pub mod definitions;
pub mod messages;
pub mod qos;
pub mod trajectory;

pub use cdr::{CdrError, CdrReader, CdrWriter};
pub use messages::Message;
