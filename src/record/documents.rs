//! The documents of a recording: the scenario's markdown (its description, what the plots show,
//! the errors in force) and the resolved config.

use rerun::RecordingStreamResult;

use super::{ReplayKind, Stream};
use crate::math::units::{ARCSEC_PER_RAD, DEG_PER_RAD, fmt_angle};
use crate::scenario::Params;

/// The documents of a run of `p` (a `replay` of that kind): the scenario explains itself (with the
/// errors in force: in live mode at `at`, on the timeline), the resolved config makes the run
/// reproducible.
pub(crate) fn log_documents(
    stream: &Stream,
    p: &Params,
    replay: Option<ReplayKind>,
    at: Option<f64>,
) -> RecordingStreamResult<()> {
    let strapdown = replay.is_some_and(|k| !k.table);
    let mut doc = format!("# {}\n\n*{}*\n\n{}\n", p.meta.name, p.meta.title, p.meta.description.trim());
    let replayed = "The INS's own solution is in `ins/body_attitude_deg` (the primary algorithm's body attitude, heading in (−180°, 180°]) \
         and, navigating, `ins/velocity_enu_mps`, `ins/position_from_start_m` and `ins/latitude_longitude_deg`. \
         Time: seconds after the replay's start on `sim_time`, the IMU file's own clock on the timeline `file_clock` (docs/export.md).";
    let plots = match replay {
        None => "Plots: red = uncompensated (nominal table model), green = compensated (`[compensation]` parameters), \
         blue = closed form (first-order theory, docs/closed-form.md)."
            .to_owned(),
        Some(ReplayKind { table: false, reference }) => format!(
            "A replayed **strapdown** IMU (no table): the 3D view shows its axes (= the body's: x right, y forward, z up) turning with the INS's attitude{}. {}",
            if reference {
                ", the reference's in grey; the error plots are the INS's attitude against the reference, per algorithm"
            } else {
                " (no reference: nothing to compare it with)"
            },
            replayed
        ),
        Some(ReplayKind { reference, .. }) => format!(
            "Plots (a replayed log): {} {replayed}",
            if reference {
                "red = the INS attitude demodulated through the nominal table, green = through the compensated table, each against the log's reference attitude."
            } else {
                "no reference: the table error plots show the nominal − the compensated demodulation."
            }
        ),
    };
    if strapdown {
        doc.push_str(&format!("\n---\n{plots}\n"));
    } else {
        doc.push_str(&format!(
            "\n---\nError angles in the 3D view are drawn **×{}**. {plots} Seed {}.\n",
            p.recording.exaggeration, p.meta.seed
        ));
    }
    if replay.is_none() {
        doc.push_str(&errors_in_force(p, at));
    }
    stream.put(at, "docs/scenario", &rerun::TextDocument::from_markdown(doc))?;
    stream.put(
        at,
        "docs/config",
        &rerun::TextDocument::from_markdown(format!("```toml\n{}\n```\n", p.resolved_toml)),
    )?;
    Ok(())
}

/// The table's true errors as a markdown table, from the parameters in force: the description
/// above was written for the preset's values, this follows every live reload.
fn errors_in_force(p: &Params, at: Option<f64>) -> String {
    let t = &p.table.truth;
    let when = at.map_or(String::new(), |t_s| format!(" since t = {t_s:.1} s"));
    let mut s = format!(
        "\n**Errors in force{when}** (true values; `[compensation]` is what the compensated line assumes)\n\n| axis | swing α | swing φ | η | encoder offset | scale | delay | noise 1σ |\n|---|---:|---:|---:|---:|---:|---:|---:|\n"
    );
    for (g, e) in p.table.chain.axes().iter().zip(&t.axes) {
        s.push_str(&format!(
            "| {} | {} | {:.1}° | {} | {} | {:.0} ppm | {:.2} ms | {} |\n",
            g.name,
            fmt_angle(e.swing_half_angle_rad),
            e.swing_phase_rad * DEG_PER_RAD,
            fmt_angle(e.non_orthogonality_rad),
            fmt_angle(e.encoder_offset_rad),
            e.encoder_scale * 1e6,
            e.encoder_delay_s * 1e3,
            fmt_angle(e.encoder_noise_rad)
        ));
    }
    let v = |x: &nalgebra::Vector3<f64>| {
        format!("({:.1}, {:.1}, {:.1})″", x.x * ARCSEC_PER_RAD, x.y * ARCSEC_PER_RAD, x.z * ARCSEC_PER_RAD)
    };
    s.push_str(&format!(
        "\nInstallation about (x, y, z): {}; IMU mounting: {}.\n",
        v(&t.installation_rad),
        v(&t.imu_mount_rad)
    ));
    s
}
