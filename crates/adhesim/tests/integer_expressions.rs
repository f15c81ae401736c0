//! Expressions in integer keys: `divisions = ["= nx", 2, "= nx / 2"]` gives the mesh a
//! parameter asks for, real keys still take whole-number expressions, and a fractional
//! value for an integer key is an error naming the key.

use std::path::Path;

fn scenario(divisions: &str) -> String {
    format!(
        r#"
[parameters]
nx = 4
g = 1e6
[time]
t_end = 1.0
dt = 0.5
mode = "quasi-static"
[[body]]
name = "b"
mesh = {{ generator = "block", size = [0.01, 0.01, 0.01], divisions = {divisions} }}
material = {{ model = "blatz-ko", g = "= g" }}
density = "= 500 * 2"
[[boundary]]
body = "b"
set = "bottom"
fix = ["x", "y", "z"]
"#
    )
}

#[test]
fn integer_keys_take_expressions() {
    let text = scenario(r#"["= nx", 2, "= nx / 2"]"#);
    let p = adhesim_io::scenario::parse(&text, Path::new("ints.toml"))
        .unwrap()
        .problem;
    let mesh = &p.bodies[0].mesh;
    // 4 × 2 × 2 hexahedra on 5 × 3 × 3 nodes.
    assert_eq!(mesh.hexes().len(), 16);
    assert_eq!(mesh.num_nodes(), 45);
    assert_eq!(p.bodies[0].density, 1000.0);
}

#[test]
fn a_fractional_value_for_an_integer_key_names_the_key() {
    let text = scenario(r#"["= nx / 3", 2, 2]"#);
    let err = adhesim_io::scenario::parse(&text, Path::new("ints.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("divisions"), "{err}");
}
