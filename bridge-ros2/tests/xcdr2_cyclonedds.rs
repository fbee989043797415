//! XCDR2 read into XCDR1 against Eclipse Cyclone DDS, an implementation
//! independent of the bridge's: every message of `ros2-map/tests/cdr_samples.py`
//! (27 types, one of them of a package of the tests' own, both byte orders) serialized by the `cyclonedds` package in
//! XCDR2 (`bridge-ros2/tests/xcdr2_samples.py`), as final types (`00 06`,
//! `00 07`) and as appendable ones (the delimited `00 08`, `00 09`), decodes,
//! once read into XCDR1, to exactly what Cyclone DDS's own XCDR1 of it
//! decodes to.
//!
//! A missing `python3` or `cyclonedds` fails the test: install the test
//! requirements with `python3 -m pip install -r examples/python/requirements.txt`.

use serde_json::Value as Json;
use situ_bridge_ros2::xcdr2;
use situ_ros2_map::cdr::Decoder;
use situ_ros2_map::msgs::{Registry, SearchPath};

fn hex(s: &str) -> Vec<u8> {
    (0..s.len()).step_by(2).map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap()).collect()
}

/// The script's lines, by message name.
fn samples(args: &[&str]) -> Vec<Json> {
    let out = std::process::Command::new("python3")
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
        .arg("bridge-ros2/tests/xcdr2_samples.py")
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot run python3 ({e}): the test needs python3 with cyclonedds"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<Json> =
        String::from_utf8(out.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 76);
    lines
}

/// Each line's XCDR2, read into XCDR1, decodes as `xcdr1`'s line of that name.
fn reads_as(xcdr2: &[Json], xcdr1: &[Json], header: [u8; 2]) {
    let own = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/ros2/msgs");
    let reg = Registry::load(&SearchPath::with_ament(&[own.into()], None));
    for (line, plain) in xcdr2.iter().zip(xcdr1) {
        let name = line["name"].as_str().unwrap();
        assert_eq!(plain["name"].as_str(), Some(name));
        let ty = reg.lookup(line["type"].as_str().unwrap()).unwrap();
        let (v1, v2) = (hex(plain["xcdr1_hex"].as_str().unwrap()), hex(line["xcdr2_hex"].as_str().unwrap()));
        let little = !name.ends_with("_be");
        assert_eq!(v2[..2], [header[0], header[1] + u8::from(little)], "{name}");
        assert!(xcdr2::is_xcdr2(&v2), "{name}");
        let decoder = Decoder::new(&reg, ty).unwrap();
        let expected = decoder.decode(&v1).unwrap_or_else(|e| panic!("{name}: XCDR1 {e}"));
        let read = xcdr2::to_xcdr1(&reg, ty, &v2).unwrap_or_else(|e| panic!("{name}: {e}"));
        let got = decoder.decode(&read).unwrap_or_else(|e| panic!("{name}: {e}"));
        // NaN is not equal to itself: compare what they print.
        assert_eq!(format!("{got:?}"), format!("{expected:?}"), "{name}");
    }
}

#[test]
fn cyclone_ddss_xcdr2_reads_as_its_xcdr1() {
    let plain = samples(&[]);
    reads_as(&plain, &plain, [0, 6]);
    reads_as(&samples(&["--appendable"]), &plain, [0, 8]);
}
