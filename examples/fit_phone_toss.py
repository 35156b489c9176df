"""
Fitting a real tumbling body
============================

Fit a real tumbling body: a phone tossed into the air, flipping about its intermediate axis.

The data (examples/tumbling_data/, see SOURCE.md there) are two phyphox gyroscope
recordings (about 100 Hz, 0.6 s each) of a phone thrown spinning near its
intermediate axis: body-frame angular velocities only, so the attitude is not
seen and the fit finds the inertia ratios and the initial rate. The two throws
are fitted separately; they must agree. Writes, into the folder given (default
``phone_fit``): the figures of each fit, and ``prediction.png``: the motion
predicted from the first throw's first 0.3 s against the rest of that throw.

Source: R. Feng (supervisor C. Bai), "Tennis Racket Effect" (Fudan University),
https://github.com/weenming/TRE, experiment/Raw Data_3.csv, commit 5d87b93.

Run::

    .venv/bin/python examples/fit_phone_toss.py [OUT]
    eulerpoisson fit examples/tumbling_data/phone_toss_1.csv --plot phone_fit/toss_1
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import eulerpoisson as ep
from eulerpoisson.io.observations import read_observations

try:
    DATA = Path(__file__).resolve().parent / "tumbling_data"
except NameError:  # sphinx-gallery runs the examples in their folder, without __file__
    DATA = Path("tumbling_data").resolve()


def main(out="phone_fit") -> dict:
    out = Path(out)
    results = {}
    for name in ("phone_toss_1", "phone_toss_2"):
        obs = read_observations(DATA / f"{name}.csv")
        res = ep.fit(**obs.fit_kwargs())
        results[name] = res
        periods = ep.analysis.tumbling_periods(np.diag(res.inertia), omega0=res.omega0)
        print(f"{name}:")
        print(res.summary())
        print(
            f"  period of Omega(t) {periods['P_omega']:.4f} s, mean precession {periods['P_phi']:.4f} s "
            f"({periods['mode']}); flips every {periods['P_omega'] / 2:.4f} s"
        )
        res.save_plots(out / name)
    a, b = (results[n] for n in ("phone_toss_1", "phone_toss_2"))
    for k in ("I_xx", "I_yy", "I_zz"):
        z = (a.parameters[k] - b.parameters[k]) / np.hypot(a.stderr[k], b.stderr[k])
        print(
            f"{k}: toss 1 {a.parameters[k]:.5f} +- {a.stderr[k]:.5f}, toss 2 {b.parameters[k]:.5f} +- "
            f"{b.stderr[k]:.5f} ({z:+.2f} sigma apart)"
        )
    # prediction: fit the first half of toss 1, predict the second half
    obs = read_observations(DATA / "phone_toss_1.csv")
    kw = obs.fit_kwargs()
    half = kw["t"] <= 0.3
    early = ep.fit(kw["t"][half], omega=kw["omega"][half])
    tt = np.linspace(0.0, kw["t"][-1], 400)
    pred = early.predict(tt)
    late = ~half
    err = np.abs(early.predict(kw["t"][late]).omega - kw["omega"][late])
    print(
        f"prediction from t <= 0.3 s of toss 1: rms error over the next {kw['t'][-1] - 0.3:.2f} s "
        f"{np.sqrt(np.mean(err**2)):.3f} rad/s (rates up to {np.abs(kw['omega']).max():.1f} rad/s)"
    )
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.4))
    for j, c in enumerate("xyz"):
        ax.plot(tt, pred.omega[:, j], color=f"C{j}", lw=1.2, label=f"predicted ω{c}")
        ax.plot(kw["t"][half], kw["omega"][half, j], "o", color=f"C{j}", ms=3)
        ax.plot(kw["t"][late], kw["omega"][late, j], "x", color=f"C{j}", ms=4)
    ax.axvline(0.3, color="0.5", ls="--", lw=0.8)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("body rate [rad/s]")
    ax.set_title("phone toss: fitted on t ≤ 0.3 s (dots), predicted after (crosses: observed)", fontsize=9)
    ax.legend(fontsize=7, ncol=3, loc="lower left")
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "prediction.png", dpi=110)
    plt.close(fig)
    return results


if __name__ == "__main__":
    main(*sys.argv[1:2])
