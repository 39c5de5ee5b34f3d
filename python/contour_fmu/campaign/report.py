"""Campaign: a finished campaign's summary (OUT/summary.md) and plots (OUT/distribution.png,
OUT/sensitivity.png).

- The distribution of each metric per variant and path (box plots; the table gives the
  median, the 95th percentile and the maximum).
- The sensitivity of the first metric to each swept parameter, per variant and path:
  Spearman's rank correlation (does the error grow with the parameter at all) and the
  elasticity (the least-squares slope scaled by mean parameter / mean error: the error's
  relative change per relative change of the parameter).
- The worst run of each variant and path by the first metric, and every run that did
  not finish, each with the command that replays it alone.
"""

import shlex
from pathlib import Path

import numpy as np

from ..extras import needs
from .metrics import unit_of

SCALE = {"mm": (1e3, "µm"), "rad": (1e6, "µrad")}


def _scaled(metric):
    return SCALE[unit_of(metric)]


def replay_command(campaign, run_id, out):
    """The command that runs one run alone, from any folder (absolute paths; the same
    FMUs when the campaign ran with --fmu-dir)."""
    fmus = f" --fmu-dir {shlex.quote(str(campaign.fmu_dir))}" if campaign.fmu_dir else ""
    return (f"python -m contour_fmu.campaign replay {shlex.quote(str(campaign.source))} "
            f"--run {run_id} --out {shlex.quote(str(Path(out).resolve() / 'replay'))}{fmus}")


def _groups(columns):
    """(variant, path) -> indices of the ok rows, in the campaign's order."""
    groups = {}
    for i, (variant, path, status) in enumerate(zip(columns["variant"], columns["path"], columns["status"])):
        groups.setdefault((variant, path), [])
        if status == "ok":
            groups[(variant, path)].append(i)
    return groups


def sensitivity(x, y):
    """(Spearman's rho, elasticity) of y against x; NaN when either is constant or x is
    not a number (a swept string)."""
    with needs("campaign"):
        from scipy.stats import spearmanr

    if any(isinstance(v, str) for v in x):
        return float("nan"), float("nan")
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 3 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return float("nan"), float("nan")
    rho = float(spearmanr(x, y).statistic)
    slope = np.polyfit(x, y, 1)[0]
    return rho, float(slope * x.mean() / y.mean())


def summary(campaign, table, out):
    """The Markdown text of OUT/summary.md."""
    c = table.to_pydict()
    metrics, first = campaign.metrics, campaign.metrics[0]
    from .store import STATUSES  # pyarrow: a campaign extra, which a summary's table needs anyway

    statuses = {s: c["status"].count(s) for s in STATUSES}
    wall = np.nansum(np.asarray(c["wall_time_s"], float))
    lines = [f"# Campaign: {campaign.name}", "",
             f"- file: `{campaign.source}`; loop {campaign.loop}; digest `{campaign.digest[:12]}`",
             f"- runs: {len(campaign.runs)} planned, {len(c['run_id'])} recorded: "
             + ", ".join(f"{n} {s}" for s, n in statuses.items()),
             f"- run time summed over workers: {wall:.1f} s", ""]
    head = "| variant | path | ok/runs | " + " | ".join(
        f"{m} median / p95 / max ({_scaled(m)[1]})" for m in metrics) + " |"
    lines += ["## Distribution per variant and path", "", head,
              "|" + "---|" * (3 + len(metrics))]
    groups = _groups(c)
    for (variant, path), rows in groups.items():
        planned = sum(1 for v, p in zip(c["variant"], c["path"]) if (v, p) == (variant, path))
        cells = []
        for m in metrics:
            factor = _scaled(m)[0]
            values = np.asarray([c[m][i] for i in rows], float) * factor
            cells.append("–" if len(values) == 0 else
                         f"{np.median(values):.4g} / {np.percentile(values, 95):.4g} / {values.max():.4g}")
        lines.append(f"| {variant} | {path} | {len(rows)}/{planned} | " + " | ".join(cells) + " |")
    lines.append("")
    if campaign.swept:
        lines += [f"## Sensitivity of {first} to each swept parameter", "",
                  "Spearman's rho / elasticity (relative change of the error per relative "
                  "change of the parameter, from a least-squares line).", "",
                  "| variant | path | " + " | ".join(campaign.swept) + " |",
                  "|" + "---|" * (2 + len(campaign.swept))]
        for (variant, path), rows in groups.items():
            y = [c[first][i] for i in rows]
            cells = []
            for name in campaign.swept:
                rho, elasticity = sensitivity([c[name][i] for i in rows], y)
                cells.append(f"{rho:+.2f} / {elasticity:+.3f}")
            lines.append(f"| {variant} | {path} | " + " | ".join(cells) + " |")
        lines.append("")
    # The worst run of each variant and path: the overall worst would all be one group's.
    worst = [max(rows, key=lambda i: c[first][i]) for rows in groups.values() if rows]
    worst.sort(key=lambda i: c[first][i], reverse=True)
    factor, unit = _scaled(first)
    lines += [f"## Worst run of each variant and path, by {first}", "",
              f"| run | variant | path | {first} ({unit}) | swept values | replay |", "|---|---|---|---|---|---|"]
    for i in worst:
        swept = ", ".join(f"{n} = {c[n][i]:.6g}" if isinstance(c[n][i], float) else f"{n} = {c[n][i]}"
                          for n in campaign.swept) or "–"
        lines.append(f"| {c['run_id'][i]} | {c['variant'][i]} | {c['path'][i]} | "
                     f"{c[first][i] * factor:.4g} | {swept} | "
                     f"`{replay_command(campaign, c['run_id'][i], out)}` |")
    lines.append("")
    failed = [i for i, s in enumerate(c["status"]) if s != "ok"]
    if failed:
        lines += ["## Runs that did not finish", "", "| run | status | message | replay |",
                  "|---|---|---|---|"]
        for i in failed:
            message = c["message"][i].replace("|", "\\|").replace("\n", " ")
            lines.append(f"| {c['run_id'][i]} | {c['status'][i]} | {message} | "
                         f"`{replay_command(campaign, c['run_id'][i], out)}` |")
        lines.append("")
    return "\n".join(lines)


def _log_if_wide(ax, data):
    """A log scale when the values span more than 20× (with and without CCC differ by
    orders of magnitude)."""
    positive = np.concatenate([d[d > 0] for d in data] + [np.empty(0)])
    if len(positive) and positive.max() > 20 * positive.min():
        ax.set_yscale("log")


def plot(campaign, table, out):
    """OUT/distribution.png and, with swept parameters, OUT/sensitivity.png."""
    with needs("campaign"):
        import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c = table.to_pydict()
    groups = _groups(c)
    labels = [f"{v}\n{p}" for v, p in groups]
    metrics = campaign.metrics
    fig, axes = plt.subplots(len(metrics), 1, figsize=(max(6.0, 1.0 * len(groups)), 3.6 * len(metrics)),
                             squeeze=False)
    for ax, m in zip(axes[:, 0], metrics):
        factor, unit = _scaled(m)
        data = [np.asarray([c[m][i] for i in rows], float) * factor for rows in groups.values()]
        ax.boxplot(data, tick_labels=labels)
        _log_if_wide(ax, data)
        ax.set_ylabel(f"{m} ({unit})"), ax.set_title(m)
        ax.tick_params(axis="x", labelsize=7)
    fig.suptitle(f"{campaign.name}: distribution per variant and path")
    fig.tight_layout()
    fig.savefig(out / "distribution.png", dpi=110)
    plt.close(fig)
    if not campaign.swept:
        return
    first = metrics[0]
    factor, unit = _scaled(first)
    n = len(campaign.swept)
    cols = min(n, 3)
    rows_ = -(-n // cols)
    fig, axes = plt.subplots(rows_, cols, figsize=(4.8 * cols, 3.8 * rows_), squeeze=False)
    for ax, name in zip(axes.flat, campaign.swept):
        data = []
        for (variant, path), rows in groups.items():
            data.append(np.asarray([c[first][i] * factor for i in rows], float))
            x = [c[name][i] for i in rows]
            ax.plot([str(v) for v in x] if any(isinstance(v, str) for v in x) else x, data[-1], ".",
                    ms=4, label=f"{variant} / {path}")
        _log_if_wide(ax, data)
        ax.set_xlabel(name), ax.set_ylabel(f"{first} ({unit})")
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=6)
    fig.suptitle(f"{campaign.name}: sensitivity of {first}")
    fig.tight_layout()
    fig.savefig(out / "sensitivity.png", dpi=110)
    plt.close(fig)


def write(campaign, table, out):
    """Writes summary.md and the plots; returns the summary text."""
    text = summary(campaign, table, out)
    (out / "summary.md").write_text(text + "\n")
    plot(campaign, table, out)
    return text
