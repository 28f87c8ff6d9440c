//! Random kinematic trees written as URDF text, for property tests.

use proptest::prelude::*;

#[derive(Clone, Debug)]
pub struct RandomLink {
    pub parent: usize,
    pub kind: &'static str,
    pub origin: [f64; 6],
    pub axis: [f64; 3],
    pub mass: f64,
    pub box_size: [f64; 3],
    pub com_pose: [f64; 6],
}

fn link() -> impl Strategy<Value = (f64, RandomLink)> {
    (
        0.0..1.0f64,
        prop::sample::select(vec!["revolute", "revolute", "continuous", "prismatic", "fixed"]),
        prop::array::uniform6(-0.4..0.4f64),
        prop::array::uniform3(-1.0..1.0f64).prop_filter("non-zero axis", |a| a.iter().map(|x| x * x).sum::<f64>() > 0.05),
        0.05..3.0f64,
        prop::array::uniform3(0.01..0.3f64),
        prop::array::uniform6(-0.2..0.2f64),
    )
        .prop_map(|(p, kind, mut origin, axis, mass, box_size, com_pose)| {
            // origin[3..] is rpy: spread it over a full turn
            for r in &mut origin[3..] {
                *r *= 7.8;
            }
            (p, RandomLink { parent: 0, kind, origin, axis, mass, box_size, com_pose })
        })
}

/// 1 to `max` links below a fixed base, each hanging from a random earlier link.
pub fn tree(max: usize) -> impl Strategy<Value = Vec<RandomLink>> {
    prop::collection::vec(link(), 1..=max).prop_map(|links| {
        links
            .into_iter()
            .enumerate()
            .map(|(i, (p, mut l))| {
                l.parent = (p * (i + 1) as f64) as usize; // 0 = base, k = link k
                l
            })
            .collect::<Vec<_>>()
    })
    .prop_filter("at least one moving joint", |links| links.iter().any(|l| l.kind != "fixed"))
}

pub fn urdf(links: &[RandomLink]) -> String {
    let mut s = String::from("<robot name=\"random\">\n<link name=\"world\"/>\n<link name=\"base\"/>\n");
    s += "<joint name=\"weld\" type=\"fixed\"><parent link=\"world\"/><child link=\"base\"/></joint>\n";
    for (i, l) in links.iter().enumerate() {
        let name = format!("l{}", i + 1);
        let parent = if l.parent == 0 { "base".to_string() } else { format!("l{}", l.parent) };
        let [a, b, c] = l.box_size;
        let m = l.mass;
        let (ixx, iyy, izz) = (m / 12.0 * (b * b + c * c), m / 12.0 * (a * a + c * c), m / 12.0 * (a * a + b * b));
        let p = l.com_pose;
        s += &format!(
            "<link name=\"{name}\"><inertial><origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/><mass value=\"{m}\"/>\
             <inertia ixx=\"{ixx}\" ixy=\"0\" ixz=\"0\" iyy=\"{iyy}\" iyz=\"0\" izz=\"{izz}\"/></inertial>\
             <visual><geometry><box size=\"{a} {b} {c}\"/></geometry></visual></link>\n",
            p[0], p[1], p[2], p[3] * 10.0, p[4] * 10.0, p[5] * 10.0
        );
        let o = l.origin;
        let ax = l.axis;
        s += &format!(
            "<joint name=\"j{}\" type=\"{}\"><parent link=\"{parent}\"/><child link=\"{name}\"/>\
             <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/><axis xyz=\"{} {} {}\"/>\
             <limit lower=\"-3\" upper=\"3\" effort=\"10\" velocity=\"5\"/><dynamics damping=\"0.1\"/></joint>\n",
            i + 1, l.kind, o[0], o[1], o[2], o[3], o[4], o[5], ax[0], ax[1], ax[2]
        );
    }
    s + "</robot>\n"
}
