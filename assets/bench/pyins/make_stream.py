#!/usr/bin/env python3
"""Generate an exact IMU-increment stream for a stationary IMU (numpy only).

Usage
-----
    python make_stream.py static  static.npy [--n 2000000] [--rate 2000] [--lat 34]
    python make_stream.py coning  coning.npy [--alpha-deg 1] [--freq 1] ...

Output: an N x 7 float64 .npy  [t_s, dtheta_x, dtheta_y, dtheta_z (rad),
dv_x, dv_y, dv_z (m/s)], body frame RFU (x right, y forward, z up).
Row k is the integral over (t_k - dt, t_k] with t_k = (k + 1) * dt, i.e. the
initial state is at t = 0 and the last row ends at N * dt (1000 s by default).
A sidecar <out>.json records the initial attitude/position to pass to the
navigator and the exact final truth.

Model (local level ENU n-frame, fixed to Earth at lat L, lon 0, h 0):
    omega_ie^n = W (0, cos L, sin L),  W = 7.292115e-5 rad/s
    f^n        = (0, 0, +g),  g = WGS84 Somigliana normal gravity at L
    static: C^n_b = I (level, heading North, RFU == ENU)
            dtheta = omega_ie^n dt,  dv = f^n dt
    coning: C^n_b(t) = K(t), K = quaternion (cos a/2, sin a/2 cos wt,
            sin a/2 sin wt, 0) (w = 2 pi freq). Body rate w.r.t. n:
            omega_nb^b = w (-sin a sin wt, sin a cos wt, -2 sin^2(a/2)).
            dtheta = int omega_nb^b dt + (int K^T dt) omega_ie^n
            dv     = (int K^T dt) f^n
            All integrals are closed-form (sum-to-product forms, no
            cancellation). Initial attitude: K(0) = rotation a about x (right)
            = pitch +a, roll 0, heading 0. With an integer number of cone
            periods in the run, the final attitude equals the initial one.
dtheta is the plain integral of the angular rate (what an increment gyro
outputs); the coning correction is left to the navigator.
"""
import argparse
import json
import numpy as np

EARTH_RATE = 7.292115e-5


def somigliana(lat_deg):
    s2 = np.sin(np.radians(lat_deg)) ** 2
    return 9.7803253359 * (1 + 0.00193185265241 * s2) / np.sqrt(1 - 0.00669437999014 * s2)


def quat_to_mat(q):
    """Rotation matrix (body -> reference) of Hamilton unit quaternions (..., 4)."""
    q0, q1, q2, q3 = np.moveaxis(q, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (q2**2 + q3**2), 2 * (q1*q2 - q0*q3), 2 * (q1*q3 + q0*q2)], -1),
        np.stack([2 * (q1*q2 + q0*q3), 1 - 2 * (q1**2 + q3**2), 2 * (q2*q3 - q0*q1)], -1),
        np.stack([2 * (q1*q3 - q0*q2), 2 * (q2*q3 + q0*q1), 1 - 2 * (q1**2 + q2**2)], -1),
    ], -2)


def coning_quat(t, alpha, w):
    t = np.asarray(t, dtype=float)
    return np.stack([np.full_like(t, np.cos(alpha / 2)),
                     np.sin(alpha / 2) * np.cos(w * t),
                     np.sin(alpha / 2) * np.sin(w * t), np.zeros_like(t)], -1)


def coning_rate(t, alpha, w):
    t = np.asarray(t, dtype=float)
    return w * np.stack([-np.sin(alpha) * np.sin(w * t), np.sin(alpha) * np.cos(w * t),
                         np.full_like(t, -2 * np.sin(alpha / 2) ** 2)], -1)


def rph_rfu_enu(C):
    """roll (right wing down), pitch (nose up), heading (cw from N, (-180,180]) in deg of C^ENU_RFU."""
    roll = np.degrees(np.arctan2(-C[2, 0], C[2, 2]))
    pitch = np.degrees(np.arcsin(C[2, 1]))
    heading = np.degrees(np.arctan2(C[0, 1], C[1, 1]))    # (-180, 180]
    return [float(roll) + 0.0, float(pitch) + 0.0, float(heading) + 0.0]


def coning_increments(n, dt, alpha, freq, wie_n, f_n):
    w = 2 * np.pi * freq
    a, b = np.cos(alpha / 2), np.sin(alpha / 2)
    k = np.arange(n, dtype=float)
    # phase of the interval midpoint, reduced to one period before scaling
    ph = 2 * np.pi * np.mod(freq * (k + 0.5) * dt, 1.0)
    sh = np.sin(w * dt / 2)       # for integrals of sin(wt), cos(wt)
    s2h = np.sin(w * dt)          # for integrals of sin^2, cos^2, sin cos
    I_s = 2 * np.sin(ph) * sh / w
    I_c = 2 * np.cos(ph) * sh / w
    I_ss = dt / 2 - np.cos(2 * ph) * s2h / (2 * w)
    I_cc = dt / 2 + np.cos(2 * ph) * s2h / (2 * w)
    I_sc = np.sin(2 * ph) * s2h / (2 * w)
    # M = int K dt (K = C^n_b); entries from quat_to_mat with q1 = b c, q2 = b s
    M = np.empty((n, 3, 3))
    M[:, 0, 0] = dt - 2 * b * b * I_ss
    M[:, 0, 1] = 2 * b * b * I_sc
    M[:, 0, 2] = 2 * a * b * I_s
    M[:, 1, 0] = 2 * b * b * I_sc
    M[:, 1, 1] = dt - 2 * b * b * I_cc
    M[:, 1, 2] = -2 * a * b * I_c
    M[:, 2, 0] = -2 * a * b * I_s
    M[:, 2, 1] = 2 * a * b * I_c
    M[:, 2, 2] = dt - 2 * b * b * dt
    dth = np.empty((n, 3))
    dth[:, 0] = -w * np.sin(alpha) * I_s
    dth[:, 1] = w * np.sin(alpha) * I_c
    dth[:, 2] = -2 * w * b * b * dt
    dth += np.einsum('kji,j->ki', M, wie_n)    # (int K^T dt) omega_ie^n
    dv = np.einsum('kji,j->ki', M, f_n)        # (int K^T dt) f^n
    return dth, dv


def self_check(alpha, freq, dt, wie_n, f_n):
    """Check the rate formula (q* x dq/dt) and the closed-form integrals (quadrature)."""
    w = 2 * np.pi * freq
    t = np.array([0.013, 0.37, 0.81, 123.4567])
    h = 1e-6
    q = coning_quat(t, alpha, w)
    qd = (coning_quat(t + h, alpha, w) - coning_quat(t - h, alpha, w)) / (2 * h)
    # omega_b = 2 * vec(q* (x) qdot)
    q0, qv = q[:, 0], q[:, 1:]
    p0, pv = qd[:, 0], qd[:, 1:]
    om = 2 * (q0[:, None] * pv - p0[:, None] * qv - np.cross(qv, pv))
    assert np.allclose(om, coning_rate(t, alpha, w), atol=1e-7), (om, coning_rate(t, alpha, w))
    # quadrature over a few intervals (Gauss-Legendre, 8 nodes: exact to ~1e-20 here)
    ks = np.array([0, 1, 777, 1999, 123456])
    dth, dv = coning_increments(ks.max() + 1, dt, alpha, freq, wie_n, f_n)
    x, wts = np.polynomial.legendre.leggauss(8)
    for k in ks:
        t0 = k * dt
        tt = t0 + (x + 1) * dt / 2
        C = quat_to_mat(coning_quat(tt, alpha, w))
        rate = coning_rate(tt, alpha, w) + np.einsum('kji,j->ki', C, wie_n)
        fb = np.einsum('kji,j->ki', C, f_n)
        q_th = (wts[:, None] * rate).sum(0) * dt / 2
        q_dv = (wts[:, None] * fb).sum(0) * dt / 2
        assert np.allclose(q_th, dth[k], rtol=0, atol=1e-15), (k, q_th - dth[k])
        assert np.allclose(q_dv, dv[k], rtol=0, atol=1e-15), (k, q_dv - dv[k])


def main():
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    p.add_argument('kind', choices=['static', 'coning'])
    p.add_argument('out')
    p.add_argument('--n', type=int, default=2_000_000)
    p.add_argument('--rate', type=float, default=2000.0, help='sample rate, Hz')
    p.add_argument('--lat', type=float, default=34.0)
    p.add_argument('--alpha-deg', type=float, default=1.0, help='cone half-angle')
    p.add_argument('--freq', type=float, default=1.0, help='coning frequency, Hz')
    a = p.parse_args()

    dt = 1.0 / a.rate
    L = np.radians(a.lat)
    g = somigliana(a.lat)
    wie_n = EARTH_RATE * np.array([0.0, np.cos(L), np.sin(L)])
    f_n = np.array([0.0, 0.0, g])
    n = a.n
    out = np.empty((n, 7))
    out[:, 0] = (np.arange(n) + 1) * dt
    if a.kind == 'static':
        out[:, 1:4] = wie_n * dt
        out[:, 4:7] = f_n * dt
        C0 = C1 = np.eye(3)
    else:
        alpha = np.radians(a.alpha_deg)
        self_check(alpha, a.freq, dt, wie_n, f_n)
        out[:, 1:4], out[:, 4:7] = coning_increments(n, dt, alpha, a.freq, wie_n, f_n)
        w = 2 * np.pi * a.freq
        C0 = quat_to_mat(coning_quat(0.0, alpha, w))
        C1 = quat_to_mat(coning_quat(n * dt, alpha, w))
    np.save(a.out, out)
    meta = {
        'kind': a.kind, 'n': n, 'rate_hz': a.rate, 'dt': dt, 't0': 0.0, 't_end': n * dt,
        'frame': 'body RFU, nav ENU; row k = integral over (t_k - dt, t_k]',
        'gravity': g, 'earth_rate': EARTH_RATE,
        'initial': {'lla': [a.lat, 0.0, 0.0], 'rph': rph_rfu_enu(C0), 'vel_enu': [0, 0, 0]},
        'truth_final': {'lla': [a.lat, 0.0, 0.0], 'rph': rph_rfu_enu(C1), 'vel_enu': [0, 0, 0]},
    }
    if a.kind == 'coning':
        meta.update(alpha_deg=a.alpha_deg, freq_hz=a.freq)
    with open(a.out.rsplit('.npy', 1)[0] + '.json', 'w') as fh:
        json.dump(meta, fh, indent=1)
    print(json.dumps(meta))


if __name__ == '__main__':
    main()
