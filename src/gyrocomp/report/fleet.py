"""The fleet report: one self-contained HTML page of a calibrated fleet.

Sections: ``summary`` (units, fitted, failed, yield against the limits, outliers), ``distributions`` (a histogram of
every figure of merit and coefficient over the fitted units, every axis overlaid, the limits dashed), ``outliers``
(the units far from their population, by robust score, with the figures that put them there), ``worst`` (the ten
highest-scoring units' figures, worst axis each), ``rejected`` (the units outside the limits and why) and
``failed`` (the units whose fit failed, with the error).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..fleet import FIGURE_NAMES, Limits, fleet_yield
from ..fleet.population import OUTLIER_THRESHOLD
from . import figures
from .page import Report, figure_html, html_page, table_html

#: units listed in the worst-units table
WORST_UNITS = 10


def build_fleet_report(table: pd.DataFrame, *, limits: Limits | None = None, title: str = "fleet") -> Report:
    """The fleet report of a fleet table (:func:`gyrocomp.fleet.fleet_table`, judged by ``limits`` when given)."""
    figures.require_matplotlib()
    axes = tuple(sorted({c[: -len(n) - 1] for c in table.columns for n in FIGURE_NAMES if c.endswith("_" + n)}))
    counts = fleet_yield(table)
    sections = {"summary": ("Summary", _summary(table, counts, limits))}
    if counts.fitted:
        sections["distributions"] = (
            "Distributions",
            figure_html(figures.fleet_distributions(table, FIGURE_NAMES, axes, limits), "histograms of every figure"),
        )
    outliers = table[table["outlier"]].sort_values("outlier_score", ascending=False)
    sections["outliers"] = (
        "Outliers",
        table_html(
            ["serial", "score", "figures", "verdict"],
            [
                [s, float(z), f, v or "-"]
                for s, z, f, v in zip(
                    outliers["serial"], outliers["outlier_score"], outliers["outlier_figures"], outliers["verdict"]
                )
            ],
            f"units whose robust z-score passes {OUTLIER_THRESHOLD} on some figure: {len(outliers)}",
        )
        if len(outliers)
        else "<p>No unit stands out of its population.</p>",
    )
    sections["worst"] = ("Worst units", _worst(table, axes))
    rejected = table[table["verdict"] == "fail"]
    if len(rejected):
        sections["rejected"] = (
            "Outside the limits",
            table_html(
                ["serial", "failing figures"], [[s, f] for s, f in zip(rejected["serial"], rejected["failing"])]
            ),
        )
    failed = table[table["status"] == "failed"]
    if len(failed):
        sections["failed"] = (
            "Failed fits",
            table_html(["serial", "error"], [[s, e] for s, e in zip(failed["serial"], failed["error"])]),
        )
    return Report(
        html_page(f"gyrocomp fleet report: {title}", f"gyrocomp fleet report: {title}", "", sections), tuple(sections)
    )


def _summary(table: pd.DataFrame, counts, limits: Limits | None) -> str:
    rows = [
        ["units", counts.units],
        ["fitted", counts.fitted],
        ["failed", counts.units - counts.fitted],
        ["outliers", int(table["outlier"].sum())],
    ]
    if limits is not None or (table["verdict"] != "").any():
        rows.append(["pass", counts.passed])
        rows.append(["yield", f"{100 * counts.yield_fraction:.1f} %"])
    text = table_html(["", "count"], rows)
    if limits is not None:
        text += table_html(
            ["figure", "axis", "min", "max", "abs_max"],
            [[lim.figure, lim.axis or "every", lim.min, lim.max, lim.abs_max] for lim in limits.limits],
            f"limits ({limits.source})",
        )
    return text


def _worst(table: pd.DataFrame, axes: tuple[str, ...]) -> str:
    """The highest-scoring units, each figure at its worst axis (largest magnitude)."""
    top = table[table["status"] == "ok"].sort_values("outlier_score", ascending=False).head(WORST_UNITS)
    if not len(top):
        return "<p>No fitted unit.</p>"
    names = [n for n in FIGURE_NAMES if any(f"{a}_{n}" in top.columns for a in axes)]
    rows = []
    for _, unit in top.iterrows():
        row = [unit["serial"], unit["verdict"] or "-", float(unit["outlier_score"])]
        for name in names:
            values = np.array([unit.get(f"{a}_{name}", np.nan) for a in axes], dtype=float)
            row.append(float(values[np.nanargmax(np.abs(values))]) if np.isfinite(values).any() else np.nan)
        rows.append(row)
    return table_html(["serial", "verdict", "score", *names], rows, "worst axis of each figure")


__all__ = ["WORST_UNITS", "build_fleet_report"]
