#!/usr/bin/env python3
"""Plots of `pvs bench` (docs/bench.md): reads the CSV files in DIR and writes
DIR/found_vs_seconds.png, DIR/found_vs_runs.png and DIR/epsilon_vs_seconds.png.

Usage: /usr/bin/python3 bench/plot_bench.py [-q] DIR

-q: print errors only (no "wrote" line, no warning when matplotlib is missing); `pvs bench -q`
passes it.

Needs matplotlib (Debian: apt-get install python3-matplotlib, for /usr/bin/python3). Exit codes:
0 plots written, 2 bad usage or unreadable CSV, 3 matplotlib missing.
"""
import csv
import math
import os
import sys
import warnings


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main(argv):
    quiet = len(argv) == 3 and argv[1] == "-q"
    if quiet:
        argv = argv[:1] + argv[2:]
        warnings.simplefilter("ignore")  # matplotlib's warnings too
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(__doc__, file=sys.stderr)
        return 2
    out = argv[1]
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        if quiet:  # a warning (the plots are skipped, pvs bench says how to make them later)
            return 3
        print(
            "plot_bench.py: matplotlib is not installed for %s; install it (Debian: "
            "apt-get install python3-matplotlib, then use /usr/bin/python3)" % sys.executable,
            file=sys.stderr,
        )
        return 3
    try:
        seg = read_csv(os.path.join(out, "growth_segment.csv"))
        pt = read_csv(os.path.join(out, "growth_point.csv"))
        qual = read_csv(os.path.join(out, "quality.csv"))
    except (OSError, csv.Error) as e:
        print("plot_bench.py: %s" % e, file=sys.stderr)
        return 2
    if not seg or not pt:
        print("plot_bench.py: empty growth CSV in %s" % out, file=sys.stderr)
        return 2

    seg_t = [float(r["seconds"]) for r in seg]
    seg_n = [int(r["found"]) for r in seg]
    seg_r = [int(r["runs"]) for r in seg]
    pt_t = [float(r["seconds"]) for r in pt]
    pt_n = [int(r["found"]) for r in pt]
    pt_r = [int(r["runs"]) for r in pt]
    t_eq, n_seg = seg_t[-1], seg_n[-1]
    within = [n for t, n in zip(pt_t, pt_n) if t <= t_eq]
    n_pt_eq = within[-1] if within else 0
    share = n_pt_eq / n_seg if n_seg else float("nan")

    # Triangles found against seconds.
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    ax.step([0] + seg_t, [0] + seg_n, where="post", color="tab:blue", label="from-segment")
    ax.step([0] + pt_t, [0] + pt_n, where="post", color="tab:orange", label="from-point")
    ax.axvline(t_eq, color="grey", ls="--", lw=0.8)
    ax.axhline(n_seg, color="tab:blue", ls=":", lw=0.8)
    ax.annotate(
        "equal time %.2f s: from-point %d / %d = %.1f%%" % (t_eq, n_pt_eq, n_seg, 100 * share),
        xy=(t_eq, n_pt_eq), xytext=(0.35, 0.12), textcoords="axes fraction",
        arrowprops=dict(arrowstyle="->", color="grey"), fontsize=9,
    )
    ax.set_xlabel("seconds (cumulative)")
    ax.set_ylabel("visible triangles found")
    ax.set_title("Triangles found against time")
    ax.set_ylim(bottom=0)
    ax.set_xlim(left=0)
    ax.grid(alpha=0.3)
    ax.legend(loc="center right")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "found_vs_seconds.png"), dpi=120)
    plt.close(fig)

    # Triangles found against runs.
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    ax.plot(seg_r, seg_n, color="tab:blue", marker=".", label="from-segment (one run = one segment, one orientation)")
    ax.plot(pt_r, pt_n, color="tab:orange", label="from-point (one run = one cubemap)")
    ax.set_xscale("log")
    ax.set_xlabel("runs")
    ax.set_ylabel("visible triangles found")
    ax.set_title("Triangles found against runs")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "found_vs_runs.png"), dpi=120)
    plt.close(fig)

    # Frame quality against seconds.
    fig, axes = plt.subplots(3, 1, figsize=(7.5, 9), sharex=True)
    colours = {"segment": "tab:blue", "point": "tab:orange"}
    names = {"segment": "from-segment", "point": "from-point"}
    rows_all = [r for r in qual if float(r["seconds"]) > 0]
    finite_psnr = [float(r["psnr"]) for r in rows_all if math.isfinite(float(r["psnr"]))]
    # Identical frames have infinite PSNR: drawn on a line above the largest finite value.
    psnr_inf = (max(finite_psnr) if finite_psnr else 40.0) + 8.0
    for method in ("segment", "point"):
        rows = [r for r in rows_all if r["method"] == method]
        if not rows:
            continue
        t = [float(r["seconds"]) for r in rows]
        eps = [100 * float(r["epsilon"]) for r in rows]
        psnr = [float(r["psnr"]) for r in rows]
        ssim = [float(r["ssim"]) for r in rows]
        c = colours[method]
        axes[0].plot(t, eps, marker="o", ms=3, color=c, label=names[method])
        axes[1].plot(t, [p if math.isfinite(p) else psnr_inf for p in psnr], color=c, lw=1,
                     label=names[method])
        axes[1].scatter(t, [p if math.isfinite(p) else psnr_inf for p in psnr], s=12, color=c,
                        marker="o")
        axes[2].plot(t, ssim, marker="o", ms=3, color=c, label=names[method])
    for ax in axes:
        ax.axvline(t_eq, color="grey", ls="--", lw=0.8)
        ax.grid(alpha=0.3)
        ax.set_xscale("log")
    axes[0].set_ylabel("pixel error ε [%] (mean)")
    # Linear below the smallest non-zero error (about one pixel), logarithmic above.
    positive = [100 * float(r["epsilon"]) for r in rows_all if float(r["epsilon"]) > 0]
    axes[0].set_yscale("symlog", linthresh=min(positive) if positive else 1e-3)
    axes[0].set_ylim(bottom=0)
    axes[1].axhline(psnr_inf, color="black", lw=0.6, ls=":")
    axes[1].annotate("identical frames (PSNR = ∞)", xy=(0.01, psnr_inf), xycoords=("axes fraction", "data"),
                     xytext=(0, 3), textcoords="offset points", fontsize=8)
    axes[1].set_ylabel("PSNR [dB] (pooled MSE)")
    axes[2].set_ylabel("SSIM (mean)")
    axes[2].set_xlabel("seconds (cumulative, log scale); dashed: from-segment total")
    axes[0].set_title("Frame quality over the test views against time")
    axes[0].legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "epsilon_vs_seconds.png"), dpi=120)
    plt.close(fig)
    if not quiet:
        print("plot_bench.py: wrote found_vs_seconds.png, found_vs_runs.png, epsilon_vs_seconds.png in %s" % out,
              file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
