//! The real-looking SmallRobotArm model (`assets/smallrobotarm/`): a URDF with STL meshes, made
//! here from the arm's published dimensions (no third-party mesh files). Run
//! `cargo run --release --bin make-smallrobotarm` to regenerate; a test checks the committed files
//! are what this writes.
//!
//! Dimensions (m): r1 = 0.047 (shoulder offset), r2 = 0.110 (upper arm), r3 = 0.026 (elbow offset),
//! d1 = 0.133 (shoulder height), d4 = 0.1175 (forearm), d6 = 0.028 (flange). Gear ratios 4.8, 4, 5,
//! 2.8, 2.1. As the tutorial's SolidWorks export: root link `base` with no world joint, five
//! actuated joints declared by `<transmission>`s (motor1..motor5, efforts 100/50/30/20/10 N·m), the
//! tool roll J6 without one and without an effort limit (passive, nearly inertia-free: the discrete plant's pitfall), no joint
//! damping, total mass ≈ 2.27 kg, and distal links so light that J4 and J5 see effective
//! inertias of ~3e-5 and ~6e-6 kg·m².

use std::fmt::Write as _;
use std::path::Path;

const R1: f64 = 0.047;
const R2: f64 = 0.110;
const R3: f64 = 0.026;
const D1: f64 = 0.133;
const D4: f64 = 0.1175;
const D6: f64 = 0.028;
const BASE_HEIGHT: f64 = 0.05;
/// Where along the forearm the roll joint J4 sits.
const J4_ALONG: f64 = 0.06;

/// A solid primitive of a link, in the link frame.
#[derive(Clone, Copy)]
enum Solid {
    /// Centre and full size.
    Box { centre: [f64; 3], size: [f64; 3] },
    /// Centre, radius, length, along axis 0 (x), 1 (y) or 2 (z).
    Cylinder { centre: [f64; 3], radius: f64, length: f64, axis: usize },
}

struct Link {
    name: &'static str,
    mass: f64,
    solids: Vec<Solid>,
    rgba: &'static str,
}

struct JointSpec {
    name: &'static str,
    parent: &'static str,
    child: &'static str,
    origin: [f64; 3],
    axis: [f64; 3],
    limit: f64,
    effort: f64,
    ratio: f64,
}

fn links() -> Vec<Link> {
    use Solid::*;
    vec![
        Link { name: "base", mass: 0.782, solids: vec![Cylinder { centre: [0.0, 0.0, BASE_HEIGHT / 2.0], radius: 0.06, length: BASE_HEIGHT, axis: 2 }], rgba: "0.3 0.3 0.33 1" },
        Link {
            name: "link1",
            mass: 0.55,
            solids: vec![
                Cylinder { centre: [0.0, 0.0, 0.035], radius: 0.045, length: 0.07, axis: 2 },
                Box { centre: [R1 / 2.0, 0.0, D1 - BASE_HEIGHT - 0.01], size: [R1 + 0.04, 0.07, 0.04] },
            ],
            rgba: "0.95 0.55 0.15 1",
        },
        Link {
            name: "link2",
            mass: 0.45,
            solids: vec![Cylinder { centre: [0.0, 0.0, 0.0], radius: 0.03, length: 0.06, axis: 1 }, Box { centre: [0.0, 0.0, R2 / 2.0], size: [0.04, 0.05, R2] }],
            rgba: "0.2 0.45 0.85 1",
        },
        Link {
            name: "link3",
            mass: 0.35,
            solids: vec![Cylinder { centre: [0.0, 0.0, 0.0], radius: 0.027, length: 0.055, axis: 1 }, Box { centre: [J4_ALONG / 2.0, 0.0, R3], size: [J4_ALONG, 0.04, 0.04] }],
            rgba: "0.95 0.55 0.15 1",
        },
        Link { name: "link4", mass: 0.12, solids: vec![Cylinder { centre: [(D4 - J4_ALONG) / 2.0, 0.0, 0.0], radius: 0.02, length: D4 - J4_ALONG, axis: 0 }], rgba: "0.2 0.45 0.85 1" },
        Link { name: "link5", mass: 0.015, solids: vec![Box { centre: [0.012, 0.0, 0.0], size: [0.024, 0.022, 0.022] }], rgba: "0.85 0.85 0.85 1" },
        Link { name: "tool", mass: 0.003, solids: vec![Cylinder { centre: [-D6 / 2.0, 0.0, 0.0], radius: 0.008, length: D6, axis: 0 }], rgba: "0.85 0.2 0.2 1" },
    ]
}

fn joints() -> Vec<JointSpec> {
    vec![
        JointSpec { name: "J1", parent: "base", child: "link1", origin: [0.0, 0.0, BASE_HEIGHT], axis: [0.0, 0.0, 1.0], limit: 3.05, effort: 100.0, ratio: 4.8 },
        JointSpec { name: "J2", parent: "link1", child: "link2", origin: [R1, 0.0, D1 - BASE_HEIGHT], axis: [0.0, 1.0, 0.0], limit: 1.57, effort: 50.0, ratio: 4.0 },
        JointSpec { name: "J3", parent: "link2", child: "link3", origin: [0.0, 0.0, R2], axis: [0.0, 1.0, 0.0], limit: 2.0, effort: 30.0, ratio: 5.0 },
        JointSpec { name: "J4", parent: "link3", child: "link4", origin: [J4_ALONG, 0.0, R3], axis: [1.0, 0.0, 0.0], limit: 3.05, effort: 20.0, ratio: 2.8 },
        JointSpec { name: "J5", parent: "link4", child: "link5", origin: [D4 - J4_ALONG, 0.0, 0.0], axis: [0.0, 1.0, 0.0], limit: 2.0, effort: 10.0, ratio: 2.1 },
        // the tool flange's roll: direct drive (ratio 1) and, as in the tutorial's export, no transmission
        JointSpec { name: "J6", parent: "link5", child: "tool", origin: [D6, 0.0, 0.0], axis: [1.0, 0.0, 0.0], limit: 3.05, effort: 0.0, ratio: 1.0 },
    ]
}

/// Mass-weighted inertia of a link's solids (uniform density): centre of mass and the inertia
/// tensor about it (diagonal: every solid is axis-aligned).
fn inertia(link: &Link) -> ([f64; 3], [f64; 3]) {
    let volume = |s: &Solid| match *s {
        Solid::Box { size, .. } => size[0] * size[1] * size[2],
        Solid::Cylinder { radius, length, .. } => std::f64::consts::PI * radius * radius * length,
    };
    let total: f64 = link.solids.iter().map(volume).sum();
    let centre = |s: &Solid| match *s {
        Solid::Box { centre, .. } | Solid::Cylinder { centre, .. } => centre,
    };
    let mut com = [0.0; 3];
    for s in &link.solids {
        let m = link.mass * volume(s) / total;
        for a in 0..3 {
            com[a] += m * centre(s)[a] / link.mass;
        }
    }
    let mut diag = [0.0; 3];
    for s in &link.solids {
        let m = link.mass * volume(s) / total;
        let own = match *s {
            Solid::Box { size: [a, b, c], .. } => [m / 12.0 * (b * b + c * c), m / 12.0 * (a * a + c * c), m / 12.0 * (a * a + b * b)],
            Solid::Cylinder { radius, length, axis, .. } => {
                let (along, across) = (0.5 * m * radius * radius, m / 12.0 * (3.0 * radius * radius + length * length));
                let mut d = [across; 3];
                d[axis] = along;
                d
            }
        };
        let c = centre(s);
        let d = [c[0] - com[0], c[1] - com[1], c[2] - com[2]];
        diag[0] += own[0] + m * (d[1] * d[1] + d[2] * d[2]);
        diag[1] += own[1] + m * (d[0] * d[0] + d[2] * d[2]);
        diag[2] += own[2] + m * (d[0] * d[0] + d[1] * d[1]);
    }
    (com, diag)
}

/// Triangles of a link's solids.
fn triangles(link: &Link) -> Vec<[[f32; 3]; 3]> {
    let mut tris = Vec::new();
    for s in &link.solids {
        match *s {
            Solid::Box { centre, size } => {
                let h = [size[0] / 2.0, size[1] / 2.0, size[2] / 2.0];
                let v = |i: usize| {
                    let sign = |bit: usize| if i >> bit & 1 == 1 { 1.0 } else { -1.0 };
                    [(centre[0] + sign(0) * h[0]) as f32, (centre[1] + sign(1) * h[1]) as f32, (centre[2] + sign(2) * h[2]) as f32]
                };
                // faces as quads of corner indices, counter-clockwise seen from outside
                for q in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
                    tris.push([v(q[0]), v(q[1]), v(q[2])]);
                    tris.push([v(q[0]), v(q[2]), v(q[3])]);
                }
            }
            Solid::Cylinder { centre, radius, length, axis } => {
                let segments = 32;
                let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
                let point = |k: usize, end: f64| {
                    let a = 2.0 * std::f64::consts::PI * k as f64 / segments as f64;
                    let mut p = centre;
                    p[axis] += end * length / 2.0;
                    p[u] += radius * a.cos();
                    p[w] += radius * a.sin();
                    p.map(|x| x as f32)
                };
                let cap = |end: f64| {
                    let mut p = centre;
                    p[axis] += end * length / 2.0;
                    p.map(|x| x as f32)
                };
                for k in 0..segments {
                    let (a0, a1, b0, b1) = (point(k, -1.0), point(k + 1, -1.0), point(k, 1.0), point(k + 1, 1.0));
                    tris.push([a0, a1, b1]);
                    tris.push([a0, b1, b0]);
                    tris.push([cap(1.0), b0, b1]);
                    tris.push([cap(-1.0), a1, a0]);
                }
            }
        }
    }
    tris
}

fn stl(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut out = Vec::with_capacity(84 + 50 * tris.len());
    let mut header = [0u8; 80];
    let text = b"armscope SmallRobotArm mesh (generated)";
    header[..text.len()].copy_from_slice(text);
    out.extend_from_slice(&header);
    out.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        let e1 = [t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]];
        let e2 = [t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]];
        let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-20);
        for x in n.iter().map(|x| x / len).chain(t.iter().flatten().copied()) {
            out.extend_from_slice(&x.to_le_bytes());
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

fn fmt3(v: [f64; 3]) -> String {
    v.iter().map(|x| format!("{}", (x * 1e9).round() / 1e9)).collect::<Vec<_>>().join(" ")
}

/// The URDF text and the meshes (file name, STL bytes).
pub fn smallrobotarm() -> (String, Vec<(String, Vec<u8>)>) {
    let mut urdf = String::from("<?xml version=\"1.0\"?>\n<!-- Generated by the make-smallrobotarm binary (src/meshgen.rs) from the SmallRobotArm's published dimensions. -->\n<robot name=\"smallrobotarm\">\n");
    let mut meshes = Vec::new();
    for link in links() {
        let (com, diag) = inertia(&link);
        let file = format!("{}.stl", link.name);
        let _ = write!(
            urdf,
            "  <link name=\"{name}\">\n    <inertial>\n      <origin xyz=\"{com}\" rpy=\"0 0 0\"/>\n      <mass value=\"{mass}\"/>\n      <inertia ixx=\"{ixx:.6e}\" ixy=\"0\" ixz=\"0\" iyy=\"{iyy:.6e}\" iyz=\"0\" izz=\"{izz:.6e}\"/>\n    </inertial>\n    <visual>\n      <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n      <geometry><mesh filename=\"package://smallrobotarm/meshes/{file}\"/></geometry>\n      <material name=\"{name}_color\"><color rgba=\"{rgba}\"/></material>\n    </visual>\n    <collision>\n      <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n      <geometry><mesh filename=\"package://smallrobotarm/meshes/{file}\"/></geometry>\n    </collision>\n  </link>\n",
            name = link.name,
            com = fmt3(com),
            mass = link.mass,
            ixx = diag[0],
            iyy = diag[1],
            izz = diag[2],
            rgba = link.rgba,
        );
        meshes.push((file, stl(&triangles(&link))));
    }
    for j in joints() {
        let _ = write!(
            urdf,
            "  <joint name=\"{}\" type=\"revolute\">\n    <parent link=\"{}\"/>\n    <child link=\"{}\"/>\n    <origin xyz=\"{}\" rpy=\"0 0 0\"/>\n    <axis xyz=\"{}\"/>\n    <limit lower=\"-{}\" upper=\"{}\" effort=\"{}\" velocity=\"3\"/>\n  </joint>\n",
            j.name, j.parent, j.child, fmt3(j.origin), fmt3(j.axis), j.limit, j.limit, j.effort
        );
    }
    for (i, j) in joints().iter().enumerate().filter(|(_, j)| j.name != "J6") {
        let _ = write!(
            urdf,
            "  <transmission name=\"trans{n}\">\n    <type>transmission_interface/SimpleTransmission</type>\n    <joint name=\"{joint}\"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>\n    <actuator name=\"motor{n}\"><mechanicalReduction>{ratio}</mechanicalReduction></actuator>\n  </transmission>\n",
            n = i + 1,
            joint = j.name,
            ratio = j.ratio
        );
    }
    urdf.push_str("</robot>\n");
    (urdf, meshes)
}

/// Write `smallrobotarm.urdf` and `meshes/*.stl` into `dir`.
pub fn write_smallrobotarm(dir: &Path) -> std::io::Result<()> {
    let (urdf, meshes) = smallrobotarm();
    std::fs::create_dir_all(dir.join("meshes"))?;
    std::fs::write(dir.join("smallrobotarm.urdf"), urdf)?;
    for (name, bytes) in meshes {
        std::fs::write(dir.join("meshes").join(name), bytes)?;
    }
    Ok(())
}
