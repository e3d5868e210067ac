"""Writing a run's reports: summary.md, summary.csv, report.html and the comparison plots."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from more_agent.eval.pictures import pictures_enabled
from more_agent.eval.report import REPORT_HTML, SUMMARY_CSV, SUMMARY_MD, SourcedRecord, summary_csv, summary_markdown
from more_agent.eval.report_html import render_report
from more_agent.safe_files import write_atomic


def write_reports(sourced: Sequence[SourcedRecord], out_dir: Path, *, title: str = "Evaluation summary") -> list[Path]:
    """Write summary.md, summary.csv, report.html and the comparison plots (PNG, unless pictures are off:
    ``eval.pictures``) into ``out_dir``, each
    all at once and never through a symlink (safe_files.write_atomic); return their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    records = [s.record for s in sourced]
    plots: list[Path] = []
    if pictures_enabled():
        from more_agent.eval.report_plots import write_plots  # matplotlib: only when pictures are drawn

        plots = write_plots(records, out_dir)
    paths = [out_dir / SUMMARY_MD, out_dir / SUMMARY_CSV, out_dir / REPORT_HTML]
    figures = "\n".join(f"![{p.stem}]({p.name})" for p in plots)
    write_atomic(paths[0], summary_markdown(records, title=title) + (f"\n## Plots\n\n{figures}\n" if plots else ""))
    write_atomic(paths[1], summary_csv(records))
    write_atomic(paths[2], render_report(sourced, title=title, out_dir=out_dir, plots=plots))
    return paths + plots
