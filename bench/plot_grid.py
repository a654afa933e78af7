# SPDX-License-Identifier: GPL-3.0-or-later
"""The benchmarks' multi-panel plots laid out to read at the manual's page width (about
700 px): at most PAGE_COLUMNS panels a row, each PANEL_SIZE inches at DPI, so a plot is
about 920 px wide and its labels keep about 3/4 of their size on the page (one click opens
it at full size)."""
from __future__ import annotations

PAGE_COLUMNS = 2
PANEL_SIZE = (4.6, 3.6)  # inches
DPI = 100


def panel_grid(count: int):
    """(figure, its count axes in reading order): PAGE_COLUMNS a row, spare cells hidden."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    count = max(count, 1)
    cols = min(count, PAGE_COLUMNS)
    rows = -(-count // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(PANEL_SIZE[0] * cols, PANEL_SIZE[1] * rows), squeeze=False)
    axes = list(axes.ravel())
    for ax in axes[count:]:
        ax.axis("off")
    return fig, axes[:count]


TITLE_CHARACTERS = 46  # a panel title's line at PANEL_SIZE's width; longer ones wrap


def save(fig, path) -> None:
    """Wrap long panel titles (they would run into the next panel), drop a log x axis's minor
    labels, lay out, write."""
    import textwrap

    from matplotlib.ticker import NullFormatter

    for ax in fig.axes:
        if ax.get_xscale() == "log":  # minor labels on a short decade run into each other
            ax.xaxis.set_minor_formatter(NullFormatter())
        title = ax.get_title()
        if len(title) > TITLE_CHARACTERS:
            ax.set_title("\n".join(textwrap.wrap(title, TITLE_CHARACTERS)))
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
