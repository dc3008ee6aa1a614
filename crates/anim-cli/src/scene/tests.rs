use super::*;

const KEPLER: &str = r#"name = "kepler"

[run]
dt = 0.005
frames = 400
steps_per_frame = 10

[scene]
kind = "kepler-orbit"
eccentricity = 0.5
integrator = "velocity-verlet"
"#;

const OSCILLATOR: &str = r#"name = "oscillator"

[run]
dt = 0.01
frames = 500
steps_per_frame = 2

[scene]
kind = "harmonic-oscillator"
mass = 1.0
stiffness = 40.0
damping = 0.2
x0 = 1.0
v0 = 0.0
integrator = "implicit-midpoint"
"#;

/// The error of parsing and building `text`.
fn err(text: &str) -> String {
    let path = Path::new("s.toml");
    match parse(text, path) {
        Err(e) => e.to_string(),
        Ok(file) => build(&file, path, Some(text)).err().map(|e| e.to_string()).unwrap_or_default(),
    }
}

fn line_of(text: &str, start: &str) -> usize {
    text.lines().position(|l| l.starts_with(start)).unwrap() + 1
}

#[test]
fn every_builtin_scene_is_a_scene_file_that_reads_back_and_builds() {
    let names = builtins();
    assert_eq!(names.len(), anim::presets().len());
    assert!(builtin(DEFAULT_SCENE).is_some());
    for (name, _) in names {
        let file = builtin(name).unwrap();
        assert_eq!(file.name, name);
        let text = toml::to_string(&file).unwrap();
        assert_eq!(parse(&text, Path::new(name)).unwrap(), file, "{name}");
    }
    // The small ones build as they are.
    for name in ["kepler", "oscillator", "rope", "panda"] {
        build(&builtin(name).unwrap(), Path::new(name), None).unwrap();
    }
}

#[test]
fn unknown_field_is_an_error_naming_file_line_and_field() {
    let text = KEPLER.replace("eccentricity = 0.5", "eccentricity = 0.5\neccentrcity = 0.2");
    let msg = err(&text);
    let line = line_of(&text, "eccentrcity");
    assert!(msg.starts_with(&format!("s.toml:{line}:")), "expected line {line}: {msg}");
    assert!(msg.contains("unknown field `eccentrcity`"), "{msg}");
    let text = KEPLER.replace("frames = 400", "frmes = 400");
    let msg = err(&text);
    assert!(
        msg.starts_with(&format!("s.toml:{}:", line_of(&text, "frmes"))) && msg.contains("frmes"),
        "{msg}"
    );
}

#[test]
fn an_unknown_kind_is_refused_on_its_line_with_the_registered_ones() {
    let text = KEPLER.replace("kepler-orbit", "warp-field");
    let msg = err(&text);
    assert!(msg.starts_with(&format!("s.toml:{}:", line_of(&text, "kind"))), "{msg}");
    assert!(msg.contains("unknown scene kind `warp-field`") && msg.contains("springs"), "{msg}");
}

#[test]
fn bad_values_name_their_field() {
    let cases = [
        (KEPLER.replace("dt = 0.005", "dt = -1.0"), "run.dt"),
        (KEPLER.replace("frames = 400", "frames = 0"), "run.frames"),
        (KEPLER.replace("eccentricity = 0.5", "eccentricity = 1.5"), "scene.eccentricity"),
        (
            KEPLER
                .replace("integrator = \"velocity-verlet\"", "integrator = { beta-blend = { beta = 2.0 } }"),
            "scene.integrator",
        ),
        (OSCILLATOR.replace("mass = 1.0", "mass = 0.0"), "scene.mass"),
        (OSCILLATOR.replace("damping = 0.2", "damping = -0.2"), "scene.damping"),
        (KEPLER.replace("name = \"kepler\"", "name = \"../x\""), "name"),
    ];
    for (text, field) in cases {
        let msg = err(&text);
        assert!(msg.contains(&format!("field `{field}`")), "{field}: {msg}");
    }
    // A parameter's error carries its line.
    let text = OSCILLATOR.replace("mass = 1.0", "mass = 0.0");
    assert!(err(&text).starts_with(&format!("s.toml:{}:", line_of(&text, "mass"))));
}

#[test]
fn unknown_names_and_wrong_types_are_errors_on_their_line() {
    let text = KEPLER.replace("velocity-verlet", "warp-drive");
    let msg = err(&text);
    assert!(msg.starts_with(&format!("s.toml:{}:", line_of(&text, "integrator"))), "{msg}");
    assert!(msg.contains("warp-drive"), "{msg}");
    let msg = err(&KEPLER.replace("frames = 400", "frames = \"many\""));
    assert!(msg.starts_with("s.toml:"), "{msg}");
}

#[test]
fn the_beta_blend_table_form_reaches_the_kind() {
    let text =
        KEPLER.replace("integrator = \"velocity-verlet\"", "integrator = { beta-blend = { beta = 0.5 } }");
    let file = parse(&text, Path::new("s.toml")).unwrap();
    let scene = build(&file, Path::new("s.toml"), Some(&text)).unwrap();
    assert_eq!(scene.method(), "beta-blend(0.5)");
}

#[test]
fn missing_file_names_the_path() {
    let msg = load(Path::new("/no/such/scene.toml")).unwrap_err().to_string();
    assert!(msg.contains("/no/such/scene.toml"), "{msg}");
}

#[test]
fn system_names_kind_and_preset() {
    assert_eq!(builtin("cloth").unwrap().scene.system(), "springs/hanging-cloth");
    assert_eq!(builtin("kepler").unwrap().scene.system(), "kepler-orbit");
}

/// A kind's refusal of a field is placed on the field's line: in `[scene]`, in its own
/// `[scene.KEY]` table, or in the `[[scene.KEY]]` table of its index, never in a later table.
#[test]
fn refused_fields_are_found_in_their_table_and_body() {
    let text = r#"name = "s"
[run]
dt = 0.01
frames = 2
[scene]
kind = "fem"
obstacles = [
    { plane = { point = [0, 0, 0], normal = [0, 0, 1] } },
]
[scene.robot]
urdf = "a.urdf"
q0 = { j = 1.0 }
[[scene.bodies]]
mesh = "a.msh"
material = { young = 1e5, poisson = 0.3, density = 1000.0 }
[[scene.bodies]]
material = { young = 1e5, poisson = 0.3, density = 1000.0 }
mesh = "b.msh"
[[scene.bodies]]
mesh = "c.msh"
"#;
    let line = |field: &str| locate(text, field).map(|at| line_col(text, at).0);
    assert_eq!(line("obstacles[0]"), Some(7));
    assert_eq!(line("robot.q0"), Some(12));
    assert_eq!(line("robot"), Some(10));
    assert_eq!(line("bodies[0].mesh"), Some(14));
    assert_eq!(line("bodies[1].mesh"), Some(18));
    assert_eq!(line("bodies[1].material.young"), Some(17));
    // A field the body does not write: its table's header.
    assert_eq!(line("bodies[2].material"), Some(19));
    assert_eq!(line("bodies[3].mesh"), None);
    assert_eq!(line("gravity"), None);
}

/// The line scanner both lookups share: a key's own line (not a longer key's, nor an earlier
/// line's), indented or not; from a table header it stops at the next table, from any other byte
/// it reads on.
#[test]
fn a_key_is_found_on_its_own_line_from_the_line_holding_the_start() {
    let text = "[scene.robot]\nkind = \"a\"\n[scene]\nkinds = 1\n  kind= \"b\"\n[scene.x]\nspeed = 2\n";
    let line = |at: Option<usize>| at.map(|at| line_col(text, at));
    let scene = table_header(text, "scene").expect("header");
    // From the header of [scene], not the `kind` of the line before it, nor `kinds`.
    assert_eq!(line(field_in_table(text, scene, "kind")), Some((5, 3)));
    assert_eq!(line(field_offset(text, scene, "kind")), Some((5, 3)));
    // A table's search ends at the next table; the other reads on.
    assert_eq!(field_in_table(text, scene, "speed"), None);
    assert_eq!(line(field_offset(text, scene, "speed")), Some((7, 1)));
    // From the middle of a line, that line is read.
    let mid = text.find("= \"a\"").expect("value");
    assert_eq!(line(field_offset(text, mid, "kind")), Some((2, 1)));
    // The unknown kind of such a file is refused on its own line.
    let file = KEPLER
        .replace("[scene]\nkind = \"kepler-orbit\"", "[scene.robot]\nkind = \"a\"\n[scene]\nkind = \"warp\"");
    let msg = err(&file);
    let kind = file.lines().position(|l| l == "kind = \"warp\"").expect("kind") + 1;
    assert!(msg.starts_with(&format!("s.toml:{kind}:")), "expected line {kind}: {msg}");
}
