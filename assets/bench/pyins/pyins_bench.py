#!/usr/bin/env python3
"""Peer-side speed benchmark: pyins 1.0.1 (python-ins) strapdown navigation.

Usage
-----
    venv/bin/python pyins_bench.py {kernel,pipeline} STREAM.npy \
        --rph ROLL PITCH HEADING --lla LAT LON HEIGHT [--vel-enu VE VN VU] [--cold]

STREAM.npy: N x 7 float64 [t_s, dtheta_x, dtheta_y, dtheta_z (rad),
dv_x, dv_y, dv_z (m/s)], plain integrals of rate / specific force over
(t_k - dt, t_k] (increment-type IMU, no coning/sculling applied), body frame
RFU (x right, y forward, z up). The initial state (--rph/--lla/--vel-enu) is at
t_0 - dt (dt = t_1 - t_0), i.e. just before the first increment.

Angles in deg, rinscope convention: heading clockwise from North, pitch nose up,
roll right wing down. Those are the same physical angles as pyins' NED/FRD
Euler angles (C^n_b = Rz(heading) Ry(pitch) Rx(roll), scipy 'xyz' extrinsic),
so they pass through unchanged; only the vector frames are converted:
    body RFU -> FRD:  x_frd = y_rfu, y_frd = x_rfu, z_frd = -z_rfu
    nav  ENU -> NED:  N = y_enu (north), E = x_enu, D = -z_enu
    i.e. both use T = [[0,1,0],[1,0,0],[0,0,-1]] (T = T^-1), C_ENU_RFU = T C_NED_FRD T.
Velocity out: pyins (VN, VE, VD) -> (east, north, up) = (VE, VN, -VD).
Heading out is in (-180, 180] (scipy as_euler).

What is timed (time.perf_counter; imports of numpy/pandas/scipy/numba excluded):
  kernel   only pyins._numba_integrate.integrate(...) over all N precomputed
           increments (increments = pyins.strapdown.compute_increments_from_imu
           on the FRD data, done before the clock starts; state arrays
           preallocated). Numba JIT is triggered beforehand by a call on a
           16-sample slice; that call's time is compile_s.
  pipeline np.load of the file -> FRD DataFrame with pyins Imu columns (plus the
           duplicated "before" sample pyins' increment convention needs, as
           pyins.sim.generate_imu does) -> compute_increments_from_imu(imu,
           'increment') -> Integrator(pva).integrate(increments) (builds the full
           Trajectory DataFrame) -> get_pva(). By default the JIT is warmed on
           a tiny dummy run first (compile_s); --cold times it inside instead.
Single-threaded (BLAS thread env vars set to 1; pyins' numba code is serial).
Output: one JSON line (seconds = wall clock; cpu_s = process CPU time of the same
region, less sensitive to other load on a shared machine; load_avg_1min for
context). peak_rss_mb = getrusage(RUSAGE_SELF).ru_maxrss of the whole process
(kernel mode includes the untimed increment preprocessing).
Needs: python-ins==1.0.1 (numba, scipy, pandas), numpy. See make_stream.py for inputs.
"""
import os
for _v in ('OMP_NUM_THREADS', 'OPENBLAS_NUM_THREADS', 'MKL_NUM_THREADS', 'NUMBA_NUM_THREADS'):
    os.environ.setdefault(_v, '1')
import argparse, importlib.metadata, json, resource, time, warnings
import numpy as np
import pandas as pd
from pyins import strapdown, transform
from pyins._numba_integrate import integrate as nb_integrate
from pyins.util import GYRO_COLS, ACCEL_COLS, THETA_COLS, DV_COLS, LLA_COLS, VEL_COLS, RPH_COLS

warnings.simplefilter('ignore', category=Warning)   # pandas-3 deprecation noise from pyins 1.0.1


def make_imu(data):
    """pyins Imu DataFrame (FRD, increments) with the leading duplicated 'before' sample."""
    n = len(data)
    t = np.empty(n + 1)
    t[1:] = data[:, 0]
    t[0] = data[0, 0] - (data[1, 0] - data[0, 0])
    vals = np.empty((n + 1, 6))
    for base in (0, 3):                               # gyro, then accel; RFU -> FRD
        vals[1:, base + 0] = data[:, base + 2]        # x_frd = y_rfu
        vals[1:, base + 1] = data[:, base + 1]        # y_frd = x_rfu
        np.negative(data[:, base + 3], out=vals[1:, base + 2])  # z_frd = -z_rfu
    vals[0] = vals[1]
    return pd.DataFrame(vals, index=pd.Index(t, name='time'), columns=GYRO_COLS + ACCEL_COLS)


def make_pva(a):
    ve, vn, vu = a.vel_enu
    return pd.Series(list(a.lla) + [vn, ve, -vu] + list(a.rph), index=LLA_COLS + VEL_COLS + RPH_COLS)


def run_pipeline(path_or_array, pva):
    data = np.load(path_or_array) if isinstance(path_or_array, str) else path_or_array
    imu = make_imu(data)
    increments = strapdown.compute_increments_from_imu(imu, 'increment')
    integrator = strapdown.Integrator(pva)
    integrator.integrate(increments)
    return len(increments), integrator.get_pva()


def kernel_state(n, pva):
    lla, vel, mat = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n + 1, 3, 3))
    lla[0], vel[0] = pva[LLA_COLS].values, pva[VEL_COLS].values
    mat[0] = transform.mat_from_rph(pva[RPH_COLS].values)
    return lla, vel, mat


def main():
    p = argparse.ArgumentParser(description='pyins 1.0.1 strapdown benchmark')
    p.add_argument('mode', choices=['kernel', 'pipeline'])
    p.add_argument('stream')
    p.add_argument('--rph', type=float, nargs=3, required=True, metavar=('ROLL', 'PITCH', 'HEADING'))
    p.add_argument('--lla', type=float, nargs=3, required=True, metavar=('LAT', 'LON', 'HEIGHT'))
    p.add_argument('--vel-enu', type=float, nargs=3, default=[0.0, 0.0, 0.0], metavar=('VE', 'VN', 'VU'))
    p.add_argument('--cold', action='store_true', help='pipeline: include JIT compile in the timing')
    a = p.parse_args()
    pva = make_pva(a)
    compile_s = None

    if a.mode == 'kernel':
        inc = strapdown.compute_increments_from_imu(make_imu(np.load(a.stream)), 'increment')
        # writable C-contiguous copies (pandas-3 .values can be read-only, which is a
        # different numba type and would trigger a second compile inside the clock)
        dt = np.array(inc['dt'].values, order='C')
        theta = np.array(inc[THETA_COLS].values, order='C')
        dv = np.array(inc[DV_COLS].values, order='C')
        n = len(theta)
        del inc
        w = 16  # warm-up on a small slice, same argument types/layouts -> same specialization
        wl, wv, wm = kernel_state(w, pva)
        t0 = time.perf_counter()
        nb_integrate(dt[:w].copy(), wl, wv, wm, theta[:w].copy(), dv[:w].copy(), 0, True)
        compile_s = time.perf_counter() - t0
        lla, vel, mat = kernel_state(n, pva)
        lla[1:], vel[1:], mat[1:] = 0.0, 0.0, 0.0   # touch pages outside the clock
        t0, c0 = time.perf_counter(), time.process_time()
        nb_integrate(dt, lla, vel, mat, theta, dv, 0, True)
        seconds, cpu_s = time.perf_counter() - t0, time.process_time() - c0
        assert len(nb_integrate.signatures) == 1, 'kernel was recompiled inside the clock'
        final = pd.Series(np.concatenate([lla[-1], vel[-1], transform.mat_to_rph(mat[-1])]),
                          index=LLA_COLS + VEL_COLS + RPH_COLS)
    else:
        if not a.cold:
            tiny = np.zeros((16, 7))
            tiny[:, 0] = np.arange(1, 17) * 5e-4
            tiny[:, 6] = 9.8 * 5e-4
            t0 = time.perf_counter()
            run_pipeline(tiny, pva)
            compile_s = time.perf_counter() - t0
        t0, c0 = time.perf_counter(), time.process_time()
        n, final = run_pipeline(a.stream, pva)
        seconds, cpu_s = time.perf_counter() - t0, time.process_time() - c0
        if not a.cold:
            assert len(nb_integrate.signatures) == 1, 'kernel was recompiled inside the clock'

    out = {
        'tool': 'python-ins ' + importlib.metadata.version('python-ins'), 'mode': a.mode,
        'cold': bool(a.cold) if a.mode == 'pipeline' else False,
        'n_samples': int(n), 'seconds': seconds, 'samples_per_s': n / seconds, 'compile_s': compile_s,
        'cpu_s': cpu_s, 'load_avg_1min': os.getloadavg()[0],
        'roll_deg': float(final['roll']), 'pitch_deg': float(final['pitch']),
        'heading_deg': float(final['heading']),
        'lat_deg': float(final['lat']), 'lon_deg': float(final['lon']), 'height_m': float(final['alt']),
        'vel_east': float(final['VE']), 'vel_north': float(final['VN']), 'vel_up': float(-final['VD']),
        'peak_rss_mb': resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }
    print(json.dumps(out))


if __name__ == '__main__':
    main()
