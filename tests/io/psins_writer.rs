//! A writer of PSINS SIMU files (`.imu`) that prints what PSINS's `imufile.m` prints, statement by
//! statement (PSINS toolbox, Gongmin Yan, NWPU: `imufile.m`'s write branch and `print_header`):
//! shared by the io tests and the replay tests (`#[path]`-included).

/// PSINS `glvs.m`: `glv.g0 = 9.7803267714`. The writer scales the accelerometer counts by
/// `glv.ug = 1e-6*glv.g0` and prints `glv.g0` with '%f' (9.780327), which the reader then uses:
/// a relative difference of 3.3e-8 that the tolerances below allow for.
pub const GLV_G0: f64 = 9.780_326_771_4;
/// `glvs.m`: `glv.deg = pi/180; glv.min = glv.deg/60; glv.sec = glv.min/60`.
pub const GLV_SEC: f64 = std::f64::consts::PI / 180.0 / 60.0 / 60.0;
/// The g header row 2 carries: `sprintf('%f', glv.g0)`.
pub const G_PRINTED: f64 = 9.780_327;

/// What `imufile(fname, imu, avp0, ts, scales, infostr)` is given, with the attitude and
/// latitude/longitude already in degrees (what its `r2d` prints).
#[derive(Clone)]
pub struct SimuInput {
    /// `imu = [wm vm t]`: increments (rad, m/s) over the previous sample and sample times (s).
    pub imu: Vec<[f64; 7]>,
    /// `[pitch roll yaw (deg), VE VN VU (m/s), lat lon (deg), h (m), t0 (s)]`, t0 >= 0.
    pub avp0: [f64; 10],
    /// Sampling interval, s.
    pub ts: f64,
    /// `[gf_x gf_y gf_z (arcsec), af_x af_y af_z (ug*s)]`.
    pub scales: [f64; 6],
}

/// The text `imufile.m`'s write branch produces for `input`, statement by statement.
pub fn imufile_text(input: &SimuInput) -> String {
    let SimuInput { imu, avp0, ts, scales: s0 } = input;
    let ts = *ts;
    // scales = [scales(1:3)*glv.sec, scales(4:6)*glv.ug];
    let ug = 1e-6 * GLV_G0;
    let scales = [s0[0] * GLV_SEC, s0[1] * GLV_SEC, s0[2] * GLV_SEC, s0[3] * ug, s0[4] * ug, s0[5] * ug];
    // t = imu(:,7)-imu(1,7)+ts+avp0(end); t = t - (1:length(t))'*ts; t = [0;diff(fix(t*1e6))];
    let t1 = imu.first().map_or(0.0, |r| r[6]);
    let fixed_us: Vec<i64> = imu
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let t = r[6] - t1 + ts + avp0[9];
            ((t - (i + 1) as f64 * ts) * 1e6).trunc() as i64
        })
        .collect();
    let dither: Vec<i64> = std::iter::once(0).chain(fixed_us.windows(2).map(|w| w[1] - w[0])).collect();
    // imu(:,k) = imu(:,k)/scales(k); imu = diff([zeros(1,6); fix(cumsum(imu,1))]);
    let mut sums = [0.0; 6];
    let mut before = [0i64; 6];
    let counts: Vec<[i64; 6]> = imu
        .iter()
        .map(|r| {
            let mut c = [0; 6];
            for k in 0..6 {
                sums[k] += r[k] / scales[k];
                let fixed = sums[k].trunc() as i64;
                c[k] = fixed - before[k];
                before[k] = fixed;
            }
            c
        })
        .collect();
    // print_header(fid, infostr), with datestr(now,31) fixed for the test.
    let mut text = String::from(concat!(
        "% PSINS-format SIMU log file. (DO NOT MODIFY!)\n",
        "% 2024-05-06 07:08:09  by Gongmin Yan\n",
        "% 1st line of the data header includes(maybe inaccurate):\n",
        "%   [pitch0(deg), roll0(deg), yaw0(deg), VE0(m/s), VN0(m/s), VU0(m/s)].\n",
        "% 2nd line of the data includes:\n",
        "%   [latitude0(deg), longitude0(deg), height0(m), t0(s), sampling-interval(ms), g(m/s^2)].\n",
        "% 3rd line of the data header includes:\n",
        "%   [gf_x, gf_y, gf_z, af_x, af_y, af_z]\n",
        "%   where gf_* is gyro scale factor in arcsec, af_* is acc scale factor in ug*s.\n",
        "% SIMU data columns include:\n",
        "%   [g_x, g_y, g_z, a_x, a_y, a_z, dt]\n",
        "%   where dt, if exists, is sampling time dither in millisecond.\n",
        "%   Conventionally, SIMU is mounted on vehicle with \"x-Right,y-Forward,z-Up\" orientations.\n\n",
    ));
    // if sum(abs(t))>0: the 7-column form, every header row ending in ' 0'.
    let seven = dither.iter().any(|&d| d != 0);
    let end = if seven { " 0" } else { "" };
    let a = avp0;
    text += &format!("{:.6} {:.6} {:.6} {:.6} {:.6} {:.6}{end}\n", a[0], a[1], a[2], a[3], a[4], a[5]);
    text += &format!("{:.8} {:.8} {:.3} {:.8} {:.8} {:.6}{end}\n", a[6], a[7], a[8], a[9], ts * 1000.0, GLV_G0);
    text += &format!("{:.6} {:.6} {:.6} {:.3} {:.3} {:.3}{end}\n\n", s0[0], s0[1], s0[2], s0[3], s0[4], s0[5]);
    for (c, d) in counts.iter().zip(&dither) {
        text += &format!("{} {} {} {} {} {}", c[0], c[1], c[2], c[3], c[4], c[5]);
        text += &if seven { format!(" {d}\n") } else { "\n".to_owned() };
    }
    text
}
