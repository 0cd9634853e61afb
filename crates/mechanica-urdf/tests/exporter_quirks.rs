//! What real robot files contain besides mechanics: `<texture/>` elements without a file,
//! inertia tensors off by rounding (zero moments written as ±1e-20), `package://` mesh URIs
//! resolved against the package's directory, declared zero-mass `<inertial>` elements, and empty
//! robots.

use mechanica_mass::MassProperties;
use mechanica_mass::validity::{ValidityTolerance, check};
use mechanica_urdf::{UrdfError, UrdfOptions, read_file, read_str};
use std::path::{Path, PathBuf};

/// A two-link arm; `material` is inserted in the robot and in the upper link's visual, and
/// `tensor` is the upper link's `<inertia>` attributes.
fn arm(material: &str, tensor: &str) -> String {
    format!(
        r#"<?xml version="1.0"?>
<robot name="arm">
  {material}
  <link name="base"/>
  <link name="upper">
    <inertial>
      <origin xyz="0 0 -0.3" rpy="0 0 0"/>
      <mass value="0.27"/>
      <inertia {tensor}/>
    </inertial>
    <visual><geometry><box size="0.1 0.1 0.6"/></geometry>{material}</visual>
  </link>
  <link name="lower">
    <inertial>
      <origin xyz="0 0 -0.25" rpy="0 0 0"/>
      <mass value="2.0"/>
      <inertia ixx="0.04" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.002"/>
    </inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="elbow" type="continuous">
    <parent link="upper"/><child link="lower"/><origin xyz="0 0 -0.6" rpy="0 0 0"/><axis xyz="0 1 0"/>
  </joint>
</robot>
"#
    )
}

const ROD: &str = r#"ixx="0.0081" ixy="0" ixz="0" iyy="0.0081" iyz="0" izz="0.0001""#;

#[test]
fn textures_without_a_file_are_ignored_and_the_rest_is_read_unchanged() {
    let here = Path::new(".");
    let plain = read_str(&arm("", ROD), here, UrdfOptions::default()).expect("plain arm");
    for material in [
        r#"<material name="grey"><color rgba="0.5 0.5 0.5 1"/><texture /></material>"#,
        r#"<material name="grey"><texture/><color rgba="0.5 0.5 0.5 1"/></material>"#,
        r#"<material name="grey"><texture></texture></material>"#,
        r#"<material name="skin"><texture filename="skin.png"/></material>"#,
    ] {
        let robot =
            read_str(&arm(material, ROD), here, UrdfOptions::default()).unwrap_or_else(|e| panic!("{material}: {e}"));
        assert_eq!(robot.links, plain.links, "{material}");
        assert_eq!(robot.joints, plain.joints, "{material}");
    }
}

#[test]
fn tensors_off_by_rounding_are_taken_as_physical_with_a_note() {
    let here = Path::new(".");
    // Point masses written with noise in their zero tensors: violations below 1e-14 of the
    // arm's largest link inertia about its frame origin (0.332 kg·m², the lower link), though
    // not of their own (zero) trace.
    for noisy in [
        r#"ixx="0" ixy="0" ixz="1.35525e-20" iyy="0" iyz="0" izz="0""#,
        r#"ixx="0" ixy="0" ixz="1e-17" iyy="0" iyz="0" izz="0""#,
        r#"ixx="-5.42e-20" ixy="0" ixz="0" iyy="-5.42e-20" iyz="0" izz="0""#,
        r#"ixx="1e-21" ixy="3e-21" ixz="0" iyy="1e-21" iyz="0" izz="0""#,
    ] {
        let robot = read_str(&arm("", noisy), here, UrdfOptions::default()).unwrap_or_else(|e| panic!("{noisy}: {e}"));
        let upper = &robot.links[1];
        assert!(
            check(&upper.mass, &ValidityTolerance::default()).is_ok(),
            "{noisy}: {:?}",
            upper.mass
        );
        assert!(
            robot
                .notes
                .iter()
                .any(|n| n.contains("link \"upper\": inertia off by rounding")),
            "{noisy}: {:?}",
            robot.notes
        );
    }
    // Violations of a real size stay errors (unless repair is asked for).
    for bad in [
        r#"ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="3e-6""#,
        r#"ixx="0.0081" ixy="0" ixz="0" iyy="0.0081" iyz="0" izz="-1e-9""#,
        // Small against the arm (3e-12 of it) but wrong by its own whole size.
        r#"ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="1e-12""#,
        // Just above the threshold: 8.5e-14 of the arm's scale.
        r#"ixx="0" ixy="0" ixz="2e-14" iyy="0" iyz="0" izz="0""#,
    ] {
        match read_str(&arm("", bad), here, UrdfOptions::default()) {
            Err(UrdfError::InvalidInertias { problems }) => {
                assert!(problems.iter().any(|p| p.contains("link \"upper\"")), "{problems:?}")
            }
            other => panic!("{bad}: {other:?}"),
        }
        let options = UrdfOptions {
            repair_inertia: true,
            ..UrdfOptions::default()
        };
        assert!(read_str(&arm("", bad), here, options).is_ok(), "{bad} with repair");
    }
}

#[test]
fn a_robot_without_links_names_the_problem() {
    let error = read_str(
        r#"<robot name="empty"></robot>"#,
        Path::new("."),
        UrdfOptions::default(),
    )
    .expect_err("no links");
    assert!(error.to_string().contains("no links"), "{error}");
}

/// A fresh directory under the system temp dir, unique to this test and process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-urdf-quirks-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// An ASCII STL of the tetrahedron with a right-angled corner at the origin and edges `a`
/// along the axes (volume a³/6), faces oriented outward.
fn corner_tetrahedron_stl(a: f64) -> String {
    let corners = [[0.0, 0.0, 0.0], [a, 0.0, 0.0], [0.0, a, 0.0], [0.0, 0.0, a]];
    let mut text = String::from("solid corner\n");
    for face in [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] {
        text.push_str("facet normal 0 0 0\nouter loop\n");
        for k in face {
            let [x, y, z] = corners[k];
            text.push_str(&format!("vertex {x} {y} {z}\n"));
        }
        text.push_str("endloop\nendfacet\n");
    }
    text.push_str("endsolid corner\n");
    text
}

#[test]
fn package_uris_are_found_under_the_package_directory() {
    // share/<package>/robots/arm.urdf with meshes in share/<package>/meshes, as installed
    // description packages are laid out, and a package named as a subdirectory of an ancestor.
    let root = scratch("package");
    let package = root.join("share").join("arm_description");
    std::fs::create_dir_all(package.join("robots")).expect("dirs");
    std::fs::create_dir_all(package.join("meshes")).expect("dirs");
    let edge = 0.2;
    std::fs::write(package.join("meshes").join("tool.stl"), corner_tetrahedron_stl(edge)).expect("mesh");
    for uri in [
        "package://arm_description/meshes/tool.stl",
        "package://share/arm_description/meshes/tool.stl",
    ] {
        let text = format!(
            r#"<robot name="r"><link name="base"/>
            <link name="tool"><collision><geometry><mesh filename="{uri}"/></geometry></collision></link>
            <joint name="j" type="revolute"><parent link="base"/><child link="tool"/><axis xyz="0 0 1"/></joint></robot>"#
        );
        let urdf = package.join("robots").join("arm.urdf");
        std::fs::write(&urdf, text).expect("urdf");
        let robot = read_file(&urdf, UrdfOptions::default()).unwrap_or_else(|e| panic!("{uri}: {e}"));
        // The tetrahedron at 1000 kg/m³ (STL stores single precision).
        let mass = 1000.0 * edge * edge * edge / 6.0;
        assert!(
            (robot.links[1].mass.mass - mass).abs() <= 1e-6 * mass,
            "{uri}: {:?}",
            robot.links[1].mass
        );
    }
    let missing = r#"<robot name="r"><link name="base"/>
        <link name="tool"><collision><geometry><mesh filename="package://other/meshes/tool.stl"/></geometry></collision></link>
        <joint name="j" type="revolute"><parent link="base"/><child link="tool"/><axis xyz="0 0 1"/></joint></robot>"#;
    let urdf = package.join("robots").join("missing.urdf");
    std::fs::write(&urdf, missing).expect("urdf");
    let error = read_file(&urdf, UrdfOptions::default()).expect_err("no package named other");
    assert!(error.to_string().contains("under package \"other\""), "{error}");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn deep_nesting_is_refused_and_markup_is_read_as_xml() {
    let here = Path::new(".");
    // Hostile depth: refused by name before any parser recurses into it.
    let deep = format!(
        r#"<robot name="r"><link name="a"/>{}{}</robot>"#,
        "<x>".repeat(100_000),
        "</x>".repeat(100_000)
    );
    let error = read_str(&deep, here, UrdfOptions::default()).expect_err("too deep");
    assert!(error.to_string().contains("nested deeper than"), "{error}");
    // A texture mentioned in a comment, a '>' inside an attribute value and a texture with a
    // file are kept; the bare texture after them is dropped and nothing else.
    let material = r#"<!-- <texture> --><material name="a>b"><texture filename="x>y.png"/>
        <texture name="nofilename"></texture ></material>"#;
    let robot = read_str(&arm(material, ROD), here, UrdfOptions::default()).expect("read");
    let plain = read_str(&arm("", ROD), here, UrdfOptions::default()).expect("plain");
    assert_eq!(robot.links, plain.links);
    assert_eq!(robot.joints, plain.joints);
}

#[test]
fn a_declared_inertial_of_zero_mass_is_followed_and_only_a_missing_one_takes_the_mesh() {
    // Tool links with the same mesh: one declares a zero-mass <inertial> (with a small tensor,
    // as exporters write for massless feet), so do two whose names need an entity or a
    // character reference and one whose tensor has a product of inertia of 1e-20 (rounding
    // noise, set to the nearest physical tensor); one has an <inertial> only inside a comment
    // and one only inside a <gazebo> block naming it. Only the last two take the mesh's mass.
    let dir = scratch("declared");
    let edge = 0.2;
    std::fs::write(dir.join("tool.stl"), corner_tetrahedron_stl(edge)).expect("mesh");
    let mesh = r#"<collision><geometry><mesh filename="tool.stl"/></geometry></collision>"#;
    let zero = r#"<inertial><origin xyz="0 0 1e-3" rpy="0 0 0"/><mass value="0.0"/>
        <inertia ixx="5.7e-7" ixy="0" ixz="0" iyy="8.4e-7" iyz="0" izz="5.3e-7"/></inertial>"#;
    let mut text = String::from(
        "<robot name=\"r\">\n<link name=\"base\"><inertial><mass value=\"1\"/>\
         <inertia ixx=\"1e-3\" ixy=\"0\" ixz=\"0\" iyy=\"1e-3\" iyz=\"0\" izz=\"1e-3\"/></inertial></link>\n",
    );
    let links = [
        ("foot", format!("{zero}{mesh}")),
        ("foot&amp;toe", format!("\n  {zero}\n  {mesh}")),
        ("foot&#38;heel", format!("{zero}{mesh}")),
        (
            "noisy",
            format!(
                r#"<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="1e-20" iyy="0" iyz="0" izz="0"/></inertial>{mesh}"#
            ),
        ),
        ("commented", format!("<!-- {zero} -->{mesh}")),
        ("gazebo_only", mesh.to_string()),
    ];
    for (i, (name, body)) in links.iter().enumerate() {
        text.push_str(&format!(
            "<link name=\"{name}\">{body}</link>\n<joint name=\"j{i}\" type=\"revolute\"><parent link=\"base\"/>\
             <child link=\"{name}\"/><axis xyz=\"0 0 1\"/></joint>\n"
        ));
    }
    text.push_str(&format!(
        "<gazebo reference=\"gazebo_only\"><link name=\"gazebo_only\">{zero}</link></gazebo>\n"
    ));
    text.push_str("</robot>\n");
    let urdf = dir.join("robot.urdf");
    std::fs::write(&urdf, &text).expect("urdf");
    let robot = read_file(&urdf, UrdfOptions::default()).unwrap_or_else(|e| panic!("{e}\n{text}"));
    let mass_of = |name: &str| {
        let link = robot
            .links
            .iter()
            .find(|l| l.name == name)
            .unwrap_or_else(|| panic!("{name}"));
        link.mass
    };
    for name in ["foot", "foot&toe", "foot&heel"] {
        let props = mass_of(name);
        assert_eq!(props.mass, 0.0, "{name}");
        assert_eq!(props.inertia_c[(1, 1)], 8.4e-7, "{name}: the declared tensor is kept");
    }
    // Eigenvalues ±1e-20: no body has that tensor, but it is the file's rounding.
    let noisy = mass_of("noisy");
    assert_eq!(noisy.mass, 0.0);
    assert!(check(&MassProperties { mass: 1.0, ..noisy }, &ValidityTolerance::default()).is_ok());
    assert!(noisy.inertia_c.amax() <= 1e-19, "{noisy:?}");
    assert!(
        robot
            .notes
            .iter()
            .any(|n| n.contains("\"noisy\"") && n.contains("rounding")),
        "{:?}",
        robot.notes
    );
    let mesh_mass = 1000.0 * edge * edge * edge / 6.0;
    for name in ["commented", "gazebo_only"] {
        let props = mass_of(name);
        assert!((props.mass - mesh_mass).abs() <= 1e-6 * mesh_mass, "{name}: {props:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
