use super::*;
use nalgebra::Vector3;
use scene::ChainPaths;

#[test]
fn quaternion_reordering_puts_w_last() {
    // nalgebra stores (w, i, j, k); Rerun wants (x, y, z, w).
    let q = UnitQuaternion::from_scaled_axis(Vector3::new(0.1, 0.2, 0.3));
    let r = to_rerun_quaternion(&q);
    assert_eq!(r.0, [q.i as f32, q.j as f32, q.k as f32, q.w as f32]);
}

#[test]
fn chain_paths_nest_outer_to_inner() {
    let p = ChainPaths::new(&["outer".into(), "inner".into()]);
    assert_eq!(p.gimbals[1], "world/vehicle/base/outer_mount/outer/inner_mount/inner");
    assert_eq!(p.imu, "world/vehicle/base/outer_mount/outer/inner_mount/inner/imu");
}

#[test]
fn each_error_class_is_drawn_large_enough_to_see() {
    // Jiang et al. 2017 at ×100: swings of 5′ and 10′ are drawn at 8.3° and 16.7° (×100 kept); the 20″
    // non-orthogonality would be 0.56°, so it gets the smallest 1-2-5 factor that draws it at 2°
    // (2°/20″ = 360 → ×500); a class that is absent keeps ×100.
    let p = crate::scenario::presets::load("jiang2017-dual-axis").expect("preset");
    let f = drawing_factors(&p.table.truth, 100.0);
    assert_eq!(f.swing, 100.0);
    assert_eq!(f.non_orthogonality, 500.0);
    assert_eq!(f.installation, 100.0);
    assert_eq!(f.imu_mount, 100.0);
    // A factor is never lowered below the scenario's, and is capped.
    let mut tiny = p.table.truth.clone();
    tiny.axes[1].non_orthogonality_rad = 1e-9;
    assert_eq!(drawing_factors(&tiny, 100.0).non_orthogonality, 1e5);
    assert_eq!(drawing_factors(&p.table.truth, 1e4).non_orthogonality, 1e4);
}
