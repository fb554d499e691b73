//! The host tests, one module a subject (`cargo test <module>::` runs one,
//! e.g. `cargo test servo_map::`). One test binary, not one a file: the
//! core is compiled and linked into the tests once, and all of them share
//! the cores.

mod behaviour_errors;
mod behaviour_head;
mod behaviour_look;
mod behaviour_modes;
mod behaviour_rest;
mod behaviour_shapes;
mod board_parts;
mod bottango;
mod console_fuzz;
mod console_parse;
mod console_readback;
mod console_service;
mod console_session;
mod dev_guide;
mod doc_transcripts;
mod driver;
mod gesture_table;
mod idle_stream;
mod motion_errors;
mod motion_properties;
mod motion_reference;
mod playback;
mod protocol_doc;
mod rate;
mod reference;
mod seeds;
mod servo;
mod servo_map;
mod settings_record;
mod settings_store;
mod show;
mod track_decoder;
mod tracking;
mod wrap_correction;

/// A file or folder in `tests/` that no `mod` line above names would never
/// be compiled (the package lists its one test binary itself): each is one.
#[test]
fn every_file_in_tests_is_a_module() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let main = include_str!("main.rs");
    let mut missing = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("tests/ is readable") {
        let path = entry.expect("tests/ is readable").path();
        let module = if path.is_dir() && path.join("mod.rs").exists() {
            path.file_name()
        } else if path.extension().is_some_and(|e| e == "rs") {
            path.file_stem()
        } else {
            continue;
        };
        let module = module.and_then(|m| m.to_str()).unwrap_or_default();
        if module != "main" && !main.contains(&format!("\nmod {module};\n")) {
            missing.push(module.to_owned());
        }
    }
    assert!(
        missing.is_empty(),
        "not a module of tests/main.rs: {missing:?}"
    );
}
