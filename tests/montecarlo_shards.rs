//! A Monte Carlo cut into shards on several processes (as a cluster's array job runs it) and merged
//! gives the statistics of the unsharded run, bit for bit but for wall time and threads.

mod common;
use common::{rinscope, scratch};

/// The JSON without the fields that measure the machine, not the result.
fn without_wall_clock(path: &std::path::Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(path).expect("json")).expect("valid json");
    let obj = v.as_object_mut().expect("object");
    obj.remove("wall_s");
    obj.remove("threads");
    v
}

#[test]
fn shards_run_in_parallel_processes_merge_into_the_unsharded_statistics() {
    let dir = scratch("merge");
    let runs = "7";
    let whole = dir.join("whole.json");
    let o = rinscope().args(["montecarlo", "--runs", runs, "--json"]).arg(&whole).output().expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Three shards at once, each its own process; 7 runs do not divide evenly (3, 2, 2).
    let children: Vec<_> = (0..3)
        .map(|k| {
            rinscope()
                .args(["montecarlo", "--runs", runs, "--shard", &format!("{k}/3"), "--json"])
                .arg(dir.join(format!("shard{k}.json")))
                .spawn()
                .expect("spawn")
        })
        .collect();
    for mut c in children {
        assert!(c.wait().expect("wait").success());
    }
    let merged = dir.join("merged.json");
    let mut merge = rinscope();
    merge.args(["montecarlo", "merge"]);
    for k in [2, 0, 1] {
        merge.arg(dir.join(format!("shard{k}.json")));
    }
    let o = merge.arg("--json").arg(&merged).output().expect("merge");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(without_wall_clock(&whole), without_wall_clock(&merged));

    // A shard missing, or given twice, is refused with exit code 2.
    let o = rinscope()
        .args(["montecarlo", "merge"])
        .arg(dir.join("shard0.json"))
        .arg(dir.join("shard1.json"))
        .output()
        .expect("merge");
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("shard 2/3 is missing"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = rinscope()
        .args(["montecarlo", "merge"])
        .arg(dir.join("shard0.json"))
        .arg(dir.join("shard0.json"))
        .output()
        .expect("merge");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("given twice"), "{}", String::from_utf8_lossy(&o.stderr));
    // A malformed shard argument.
    let o = rinscope().args(["montecarlo", "--runs", runs, "--shard", "3/3"]).output().expect("run");
    assert_eq!(o.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).ok();
}
