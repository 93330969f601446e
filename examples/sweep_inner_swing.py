"""Sweep the inner shaft's swing-cone half-angle of Jiang et al. 2017's dual-axis table and plot the
peak heading error: the example of the Python package (README, "From Python"). The same as
sweep_inner_swing.ipynb, which also shows the last run's recording inline; CI runs this script.

    pip install rinscope-*.whl matplotlib      # or: pip install ./python
    python examples/sweep_inner_swing.py        # writes sweep_inner_swing.png and a recording
"""
import matplotlib

matplotlib.use("Agg")  # a file, no window (in a notebook, leave this out)
import matplotlib.pyplot as plt
import numpy as np

import rinscope

s = rinscope.load("jiang2017-dual-axis")
alphas = np.linspace(0.0, 900.0, 10)  # the inner swing half-angle α1, arcsec (the paper's is 300″)
peaks = []
for alpha in alphas:
    s.turntable.axis["inner"].swing_half_angle_arcsec = float(alpha)  # validated like the TOML
    peaks.append(rinscope.run(s).summary["attitude_error_arcsec"]["uncompensated"]["heading"]["peak_arcsec"])
plt.plot(alphas, peaks, "o-")
plt.xlabel("inner swing half-angle α1 (arcsec)")
plt.ylabel("peak heading error, uncompensated (arcsec)")
plt.title("Jiang et al. 2017 dual-axis table, 360 s at 10°/s")
plt.savefig("sweep_inner_swing.png", dpi=120)

for alpha, peak in zip(alphas, peaks):
    print(f"α1 = {alpha:6.1f}″   peak heading error = {peak:8.2f}″")
last = rinscope.run(s, save="recordings/sweep_inner_swing.rrd")  # in a notebook: last.show()
print(f"figure: sweep_inner_swing.png; last run's recording: {last.recording} (open it with: rerun {last.recording})")
