"""Single figures, written atomically as PNG, SVG or PDF (from the suffix)."""

from __future__ import annotations

import os

import numpy as np

from ..allan import BIAS_INSTABILITY_FACTOR
from ..errors import InputError
from ..io.atomic import atomic_path
from ..noise import NoiseAnalysis

FIGURE_SUFFIXES = (".png", ".svg", ".pdf")


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise InputError("plots need matplotlib: pip install 'gyrocomp[plot]'") from exc
    return plt


def check_figure_path(path) -> str:
    """The figure format of ``path`` from its suffix; InputError for one matplotlib is not asked to write."""
    suffix = os.path.splitext(str(path))[1].lower()
    if suffix not in FIGURE_SUFFIXES:
        raise InputError(f"{path}: figure suffix {suffix!r} is not one of {', '.join(FIGURE_SUFFIXES)}")
    return suffix


def allan_figure(analysis: NoiseAnalysis, path: str | os.PathLike) -> None:
    """Log-log Allan curves of every axis with their 68 % intervals, the fitted IEEE 952 model (dashed)
    and the bias-instability floor (dotted) at the integration time."""
    suffix = check_figure_path(path)
    plt = _pyplot()
    # a constant channel (all deviations zero) has nothing to draw on log axes
    drawable = {name: a for name, a in analysis.axes.items() if np.any(a.curve.deviation > 0)}
    if not drawable:
        raise InputError(f"{analysis.source}: every analysed channel is constant; nothing to plot")
    units = sorted({a.unit for a in drawable.values()})
    fig, panels = plt.subplots(1, len(units), figsize=(7.0 * len(units), 5.0), squeeze=False)
    for panel, unit in zip(panels[0], units):
        for name, a in drawable.items():
            if a.unit != unit:
                continue
            c = a.curve
            errors = np.vstack([c.deviation - c.ci_low, c.ci_high - c.deviation])
            line = panel.errorbar(c.tau, c.deviation, yerr=np.nan_to_num(errors), fmt="o-", ms=3, capsize=2,
                                  label=f"{name} ({c.kind})")[0]
            terms = a.terms
            panel.plot(a.allan.tau, terms.model_deviation(a.allan.tau), "--", color=line.get_color(), lw=1)
            panel.plot([terms.integration_time_s], [terms.bias_instability * BIAS_INSTABILITY_FACTOR], "v",
                       color=line.get_color())
        panel.set_xscale("log")
        panel.set_yscale("log")
        panel.set_xlabel("averaging time tau [s]")
        panel.set_ylabel(f"deviation [{unit}]")
        panel.grid(True, which="both", alpha=0.3)
        panel.legend(fontsize="small")
    fig.suptitle(f"Allan deviation: {os.path.basename(analysis.source)}  "
                 "(dashed: IEEE 952 fit; triangle: bias-instability floor)", fontsize="medium")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=suffix[1:], dpi=120)
    plt.close(fig)
