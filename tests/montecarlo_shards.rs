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

/// `selfcal --monte-carlo` cut into shards on separate processes (the array tasks of
/// assets/cluster/selfcal-montecarlo.slurm) and merged: the unsharded statistics, bit for bit.
#[test]
fn selfcal_shards_merge_into_the_unsharded_statistics() {
    let dir = scratch("selfcal-merge");
    let whole = dir.join("whole.json");
    let o = rinscope()
        .args(["selfcal", "--monte-carlo", "3", "--no-recording", "--navigate-hours", "0", "--json"])
        .arg(&whole)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let children: Vec<_> = (0..2)
        .map(|k| {
            rinscope()
                .args(["selfcal", "--monte-carlo", "3", "--shard", &format!("{k}/2"), "--json"])
                .arg(dir.join(format!("shard{k}.json")))
                .spawn()
                .expect("spawn")
        })
        .collect();
    for mut c in children {
        assert!(c.wait().expect("wait").success());
    }
    let merged = dir.join("merged.json");
    let o = rinscope()
        .args(["selfcal", "--merge"])
        .arg(dir.join("shard1.json"))
        .arg(dir.join("shard0.json"))
        .arg("--json")
        .arg(&merged)
        .output()
        .expect("merge");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let read = |p: &std::path::Path| -> serde_json::Value {
        let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(p).expect("json")).expect("valid");
        v["monte_carlo"].as_object_mut().expect("monte_carlo").remove("wall_s");
        v["monte_carlo"].clone()
    };
    assert_eq!(read(&whole), read(&merged));
    // A shard missing: refused, exit 2, named.
    let o = rinscope().args(["selfcal", "--merge"]).arg(dir.join("shard0.json")).output().expect("merge");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("shard 1/2 is missing"));
    // --shard without --json: refused by the parser (nowhere to write the runs).
    let o = rinscope().args(["selfcal", "--monte-carlo", "3", "--shard", "0/2"]).output().expect("run");
    assert_eq!(o.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).ok();
}
