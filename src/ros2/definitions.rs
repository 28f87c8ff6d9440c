//! The `.msg` definitions of the messages armscope writes and reads, and the complete definition
//! (ros2msg) an MCAP schema carries: the type's own text, then each type it uses, recursively, each
//! after a line of 80 `=` and `MSG: pkg/Type`, as rosbag2 writes them
//! (`rosbag2_cpp`'s `LocalMessageDefinitionSource`, documented in rosbag2's
//! `docs/message_definition_encoding.md`). The standard types' field lines are those of ROS 2
//! Humble's common_interfaces and rcl_interfaces (Humble and Jazzy agree on all of them) and of
//! control_msgs' Humble branch (a bag's own schema says how its controller states are laid out:
//! [`super::trajectory`]); armscope's own are `assets/ros2/armscope_msgs/msg/*.msg`.

/// A type's own definition and the types its fields use.
struct Definition {
    name: &'static str,
    text: &'static str,
    uses: &'static [&'static str],
}

const DEFINITIONS: &[Definition] = &[
    Definition { name: "builtin_interfaces/msg/Time", text: "int32 sec\nuint32 nanosec\n", uses: &[] },
    Definition { name: "builtin_interfaces/msg/Duration", text: "int32 sec\nuint32 nanosec\n", uses: &[] },
    Definition { name: "std_msgs/msg/Header", text: "builtin_interfaces/Time stamp\nstring frame_id\n", uses: &["builtin_interfaces/msg/Time"] },
    Definition { name: "std_msgs/msg/String", text: "string data\n", uses: &[] },
    Definition { name: "std_msgs/msg/ColorRGBA", text: "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n", uses: &[] },
    Definition {
        name: "sensor_msgs/msg/JointState",
        text: "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
        uses: &["std_msgs/msg/Header"],
    },
    Definition { name: "sensor_msgs/msg/CompressedImage", text: "std_msgs/Header header\nstring format\nuint8[] data\n", uses: &["std_msgs/msg/Header"] },
    Definition { name: "geometry_msgs/msg/Vector3", text: "float64 x\nfloat64 y\nfloat64 z\n", uses: &[] },
    Definition { name: "geometry_msgs/msg/Point", text: "float64 x\nfloat64 y\nfloat64 z\n", uses: &[] },
    Definition { name: "geometry_msgs/msg/Quaternion", text: "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n", uses: &[] },
    Definition { name: "geometry_msgs/msg/Pose", text: "Point position\nQuaternion orientation\n", uses: &["geometry_msgs/msg/Point", "geometry_msgs/msg/Quaternion"] },
    Definition { name: "geometry_msgs/msg/PoseStamped", text: "std_msgs/Header header\nPose pose\n", uses: &["std_msgs/msg/Header", "geometry_msgs/msg/Pose"] },
    Definition { name: "geometry_msgs/msg/Transform", text: "Vector3 translation\nQuaternion rotation\n", uses: &["geometry_msgs/msg/Vector3", "geometry_msgs/msg/Quaternion"] },
    Definition {
        name: "geometry_msgs/msg/TransformStamped",
        text: "std_msgs/Header header\nstring child_frame_id\nTransform transform\n",
        uses: &["std_msgs/msg/Header", "geometry_msgs/msg/Transform"],
    },
    Definition { name: "tf2_msgs/msg/TFMessage", text: "geometry_msgs/TransformStamped[] transforms\n", uses: &["geometry_msgs/msg/TransformStamped"] },
    Definition { name: "visualization_msgs/msg/UVCoordinate", text: "float32 u\nfloat32 v\n", uses: &[] },
    Definition { name: "visualization_msgs/msg/MeshFile", text: "string filename\nuint8[] data\n", uses: &[] },
    Definition {
        name: "visualization_msgs/msg/Marker",
        text: "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\nint32 LINE_LIST=5\nint32 CUBE_LIST=6\n\
int32 SPHERE_LIST=7\nint32 POINTS=8\nint32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\nint32 ADD=0\nint32 MODIFY=0\n\
int32 DELETE=2\nint32 DELETEALL=3\nstd_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\n\
geometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\nbuiltin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n\
std_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage texture\nUVCoordinate[] uv_coordinates\nstring text\n\
string mesh_resource\nMeshFile mesh_file\nbool mesh_use_embedded_materials\n",
        uses: &[
            "std_msgs/msg/Header",
            "geometry_msgs/msg/Pose",
            "geometry_msgs/msg/Vector3",
            "std_msgs/msg/ColorRGBA",
            "builtin_interfaces/msg/Duration",
            "geometry_msgs/msg/Point",
            "sensor_msgs/msg/CompressedImage",
            "visualization_msgs/msg/UVCoordinate",
            "visualization_msgs/msg/MeshFile",
        ],
    },
    Definition { name: "visualization_msgs/msg/MarkerArray", text: "Marker[] markers\n", uses: &["visualization_msgs/msg/Marker"] },
    Definition { name: "std_msgs/msg/MultiArrayDimension", text: "string label\nuint32 size\nuint32 stride\n", uses: &[] },
    Definition { name: "std_msgs/msg/MultiArrayLayout", text: "MultiArrayDimension[] dim\nuint32 data_offset\n", uses: &["std_msgs/msg/MultiArrayDimension"] },
    Definition { name: "std_msgs/msg/Float64MultiArray", text: "MultiArrayLayout layout\nfloat64[] data\n", uses: &["std_msgs/msg/MultiArrayLayout"] },
    Definition { name: "geometry_msgs/msg/Twist", text: "Vector3 linear\nVector3 angular\n", uses: &["geometry_msgs/msg/Vector3"] },
    Definition {
        name: "trajectory_msgs/msg/JointTrajectoryPoint",
        text: "float64[] positions\nfloat64[] velocities\nfloat64[] accelerations\nfloat64[] effort\nbuiltin_interfaces/Duration time_from_start\n",
        uses: &["builtin_interfaces/msg/Duration"],
    },
    Definition {
        name: "trajectory_msgs/msg/MultiDOFJointTrajectoryPoint",
        text: "geometry_msgs/Transform[] transforms\ngeometry_msgs/Twist[] velocities\ngeometry_msgs/Twist[] accelerations\nbuiltin_interfaces/Duration time_from_start\n",
        uses: &["geometry_msgs/msg/Transform", "geometry_msgs/msg/Twist", "builtin_interfaces/msg/Duration"],
    },
    Definition {
        name: "trajectory_msgs/msg/JointTrajectory",
        text: "std_msgs/Header header\nstring[] joint_names\nJointTrajectoryPoint[] points\n",
        uses: &["std_msgs/msg/Header", "trajectory_msgs/msg/JointTrajectoryPoint"],
    },
    // control_msgs' humble branch (its comments left out)
    Definition {
        name: "control_msgs/msg/JointTrajectoryControllerState",
        text: "std_msgs/Header header\nstring[] joint_names\ntrajectory_msgs/JointTrajectoryPoint reference\n\
trajectory_msgs/JointTrajectoryPoint feedback\ntrajectory_msgs/JointTrajectoryPoint error\ntrajectory_msgs/JointTrajectoryPoint output\n\
trajectory_msgs/JointTrajectoryPoint desired\ntrajectory_msgs/JointTrajectoryPoint actual\nstring[] multi_dof_joint_names\n\
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_reference\ntrajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_feedback\n\
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_error\ntrajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_output\n\
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_desired\ntrajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_actual\n",
        uses: &["std_msgs/msg/Header", "trajectory_msgs/msg/JointTrajectoryPoint", "trajectory_msgs/msg/MultiDOFJointTrajectoryPoint"],
    },
    Definition { name: "armscope_msgs/msg/ControllerTelemetry", text: include_str!("../../assets/ros2/armscope_msgs/msg/ControllerTelemetry.msg"), uses: &[] },
    Definition { name: "armscope_msgs/msg/CollisionState", text: include_str!("../../assets/ros2/armscope_msgs/msg/CollisionState.msg"), uses: &[] },
];

fn definition(name: &str) -> Option<&'static Definition> {
    DEFINITIONS.iter().find(|d| d.name == name)
}

/// The complete ros2msg definition of `name` ("sensor_msgs/msg/JointState"); None for a type
/// armscope does not know.
pub fn full_definition(name: &str) -> Option<String> {
    let top = definition(name)?;
    let mut out = top.text.to_string();
    let mut seen = vec![top.name];
    let mut stack: Vec<&str> = top.uses.iter().rev().copied().collect();
    while let Some(next) = stack.pop() {
        if seen.contains(&next) {
            continue;
        }
        seen.push(next);
        let d = definition(next)?;
        // "pkg/msg/Type" is written "pkg/Type" after MSG:
        out += &format!("\n{}\nMSG: {}\n{}", "=".repeat(80), d.name.replacen("/msg/", "/", 1), d.text);
        stack.extend(d.uses.iter().rev());
    }
    Some(out)
}

/// Every type armscope has a definition of.
pub fn known_types() -> impl Iterator<Item = &'static str> {
    DEFINITIONS.iter().map(|d| d.name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn complete_definitions_carry_every_type_used_once() {
        let text = full_definition("tf2_msgs/msg/TFMessage").unwrap();
        assert!(text.starts_with("geometry_msgs/TransformStamped[] transforms\n\n===="));
        for dep in ["MSG: geometry_msgs/TransformStamped\n", "MSG: std_msgs/Header\n", "MSG: builtin_interfaces/Time\n", "MSG: geometry_msgs/Transform\n", "MSG: geometry_msgs/Vector3\n", "MSG: geometry_msgs/Quaternion\n"] {
            assert_eq!(text.matches(dep).count(), 1, "{dep} in {text}");
        }
        // every type any definition uses is defined
        for d in DEFINITIONS {
            for used in d.uses {
                assert!(definition(used).is_some(), "{} uses {used}", d.name);
            }
            assert!(full_definition(d.name).is_some());
        }
        assert!(full_definition("sensor_msgs/msg/Imu").is_none());
    }
}
