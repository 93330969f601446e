use super::*;

fn raw_imu(file: &str, layout: &str) -> RawImuFile {
    RawImuFile {
        file: file.into(),
        layout: layout.into(),
        kind: None,
        rate_hz: Some(100.0),
        frame: None,
        time: None,
        topic: None,
        columns: None,
        gap_policy: "refuse".into(),
        gap_factor: 3.0,
    }
}

#[test]
fn psins_imu_by_name_and_when_no_layout_is_given() {
    let dir = std::env::temp_dir().join(format!("rinscope-logset-psins-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    // imufile.m's first line; the reader checks the rest.
    std::fs::write(dir.join("trj.txt"), "% PSINS-format SIMU log file. (DO NOT MODIFY!)\n").expect("write");
    std::fs::write(dir.join("imu.csv"), "t_s,dtheta_x_rad\n").expect("write");
    let c = Checker { origin: "log.toml" };
    let layout = |file: &str, name: &str| imu_file(&c, &dir, &raw_imu(file, name)).map(|f| f.layout);
    assert_eq!(layout("trj.txt", "psins-imu").ok(), Some(Layout::PsinsImu));
    assert_eq!(layout("trj.txt", "").ok(), Some(Layout::PsinsImu));
    assert_eq!(layout("imu.csv", "").ok(), Some(Layout::Rinscope));
    // A file that is missing or not a regular file is refused with the manifest (issue 20).
    let e = layout("missing.csv", "").expect_err("missing").to_string();
    assert!(e.contains("imu.file") && e.contains("missing.csv"), "{e}");
    let e = layout("trj.txt", "psins-simu").expect_err("not a layout").to_string();
    assert!(e.contains("\"psins-imu\""), "{e}");
    // An absent key is the empty layout, and is not written back.
    let raw: RawImuFile = toml::from_str("file = \"trj.txt\"\nrate_hz = 100.0\n").expect("parse");
    assert_eq!(raw.layout, "");
    assert!(!toml::to_string(&raw).expect("serialise").contains("layout"));
    let _ = std::fs::remove_dir_all(&dir);
}
