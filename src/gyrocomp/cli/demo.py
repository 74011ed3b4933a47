"""``gyrocomp demo``: parse its options, call the library, print the result."""

from __future__ import annotations

from pathlib import Path

import click

from ..report.demo import run_demo
from .common import make_console, echo
from .render import print_evaluation, print_validation


@click.command()
@click.option(
    "-o",
    "--output",
    "out_dir",
    default="gyrocomp-demo",
    show_default=True,
    type=click.Path(file_okay=False),
    help="Folder for the demo's files.",
)
@click.pass_context
def demo(ctx, out_dir):
    """The main job on built-in simulated data: fit on chamber runs, compensate a held-out run, score it,
    and write the HTML report."""

    result = run_demo(Path(out_dir))
    if result.report_skipped:
        echo(f"gyrocomp: note: no report.html: {result.report_skipped}", err=True)
    if not ctx.obj["quiet"]:
        console = make_console()
        console.print(result.summary)
        print_validation(result.validation)
        print_evaluation(result.evaluation, title="held-out run, raw vs compensated")
        console.print(f"files in {out_dir}/: " + ", ".join(sorted(p.name for p in Path(out_dir).iterdir())))


__all__ = ["demo"]
