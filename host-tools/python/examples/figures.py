"""The seed paper's Figure 6 for a run and the margin plot for a kick
campaign, drawn with matplotlib from the Python API, cell by cell as in a
notebook.

    python host-tools/python/examples/figures.py RUN00001.WBL [CAMPAIGN_DIR] [-o OUT_DIR]

Writes figure6.png (steering, roll, yaw rate and speed against time) and,
with a campaign, margin.png (each kick's damping against speed, the fitted
trend and the predicted wobble speed with its 95 % interval).
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import polars as pl  # noqa: E402

import wobblog  # noqa: E402


def figure6(log_path, out):
    # %% The run's frames and the roll estimate, one row per 10 ms frame.
    log = wobblog.open(log_path)
    frames = log.frames(columns=["t_s", "steer_deg", "gz_dps", "speed_mps"]).to_polars()
    roll = log.roll().to_polars()
    df = frames.join(roll, on="t_s")
    episodes = log.episodes()["episodes"]

    # %% Four panels sharing time, the episodes shaded.
    panels = [("steer_deg", "steering (deg)"), ("roll_deg", "roll (deg)"),
              ("gz_dps", "yaw rate (deg/s)"), ("speed_mps", "speed (m/s)")]
    fig, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(8, 8))
    for ax, (column, label) in zip(axes, panels):
        ax.plot(df["t_s"], df[column], lw=0.7)
        ax.set_ylabel(label)
        for e in episodes:
            ax.axvspan(e["onset_s"], e["end_s"], color="tab:red", alpha=0.15)
    axes[-1].set_xlabel("time since boot (s)")
    axes[0].set_title(f"{Path(log_path).name}: {len(episodes)} wobble episode(s)")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def margin_plot(campaign, out):
    # %% Every kick of the campaign and the prediction made from them.
    m = wobblog.margin(campaign)
    kicks = pl.DataFrame(m.kicks).select("speed_mps", "sigma_per_s", "sigma_sd_per_s", "used")

    # %% Damping against speed: the kicks, the trend, the crossing and its interval.
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for used, style in ((True, "o"), (False, "x")):
        k = kicks.filter(pl.col("used") == used)
        ax.errorbar(k["speed_mps"], k["sigma_per_s"], yerr=1.96 * k["sigma_sd_per_s"],
                    fmt=style, label="kicks used" if used else "kicks rejected")
    top = max([kicks["speed_mps"].max()] + [v for v in m.ci95_mps if v is not None]
              + ([m.wobble_speed_mps] if m.wobble_speed_mps else []))
    if m.coefficients:
        a, b, c = m.coefficients
        u = [top * 1.1 * i / 100 for i in range(101)]
        ax.plot(u, [a + b * x + c * x * x for x in u], label=f"{m.trend} trend")
    if m.wobble_speed_mps is not None:
        lo, hi = m.ci95_mps
        ax.axvline(m.wobble_speed_mps, color="tab:red",
                   label=f"wobble speed {m.wobble_speed_mps:.2f} m/s")
        ax.axvspan(lo, hi if hi is not None else top * 1.1, color="tab:red", alpha=0.1,
                   label="95 % interval")
    ax.axhline(0.0, color="black", lw=0.5)
    ax.set_xlabel("speed (m/s)")
    ax.set_ylabel("sigma (1/s)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("campaign", nargs="?")
    parser.add_argument("-o", "--out", default=".")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    figure6(args.log, out / "figure6.png")
    if args.campaign:
        margin_plot(args.campaign, out / "margin.png")


if __name__ == "__main__":
    main()
