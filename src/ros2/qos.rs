//! The `offered_qos_profiles` of an MCAP channel, as rosbag2 writes them (`rosbag2_storage`'s
//! `serialize_rclcpp_qos_vector`): a YAML list of one profile, its policies as numbers (rosbag2's
//! metadata before version 9, which every later rosbag2 still reads when a file carries no
//! `rosbag2` metadata record: `rmw` values, KEEP_LAST 1, RELIABLE 1, TRANSIENT_LOCAL 1, VOLATILE 2,
//! liveliness AUTOMATIC 1), the durations "as long as possible" as rmw's infinite duration.

/// A publisher's QoS.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Qos {
    /// Reliable, keep the last `depth`, volatile: a stream of states.
    Stream { depth: u32 },
    /// Reliable, keep the last one, transient local: a late subscriber gets the last message (a
    /// robot description, static transforms).
    Latched,
}

impl Qos {
    /// The YAML rosbag2 writes into the channel's `offered_qos_profiles`.
    pub fn yaml(self) -> String {
        let (depth, durability) = match self {
            Qos::Stream { depth } => (depth, 2),
            Qos::Latched => (1, 1),
        };
        // rmw's RMW_DURATION_INFINITE {9223372036, 854775807}
        let infinite = "    sec: 9223372036\n    nsec: 854775807\n";
        format!(
            "- history: 1\n  depth: {depth}\n  reliability: 1\n  durability: {durability}\n  deadline:\n{infinite}  lifespan:\n{infinite}  liveliness: 1\n  liveliness_lease_duration:\n{infinite}  avoid_ros_namespace_conventions: false\n"
        )
    }
}
