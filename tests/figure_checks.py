"""What a reader needs from a figure, read back from matplotlib's own artists and extents.

- every legend entry stands for something drawn (:func:`undrawn_legend_entries`);
- every axis label of a panel with data names a unit in brackets and holds no raw key such as
  ``steady_speed_m_s`` (:func:`bad_axis_labels`);
- no text (annotation, note, legend inside a panel) lies over data: a line's path or a bar, in display
  coordinates after drawing (:func:`texts_over_data`).
"""

from __future__ import annotations

import re

import matplotlib.colors as mcolors
import numpy as np
from matplotlib.collections import Collection
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle
from matplotlib.text import Text

RAW_KEY = re.compile(r"\b[a-z][a-z0-9]*(?:_[a-z0-9]+){2,}\b")  # steady_speed_m_s, energy_per_metre_j_m
UNIT = re.compile(r"\[[^\]]+\]")


def _rgba(colour):
    return None if colour is None or (isinstance(colour, str) and colour == "none") else \
        tuple(np.round(mcolors.to_rgba(colour), 3))


def _line_drawn(line: Line2D) -> bool:
    if not line.get_visible():
        return False
    x = np.asarray(line.get_xdata(orig=False), dtype=float)
    y = np.asarray(line.get_ydata(orig=False), dtype=float)
    finite = int(np.sum(np.isfinite(x) & np.isfinite(y)))
    has_marker = line.get_marker() not in (None, "None", "none", "", " ")
    has_line = line.get_linestyle() not in ("None", "none", "", " ")
    return finite >= (1 if has_marker else 2) and (has_marker or has_line)


def _matches(handle, artist) -> bool:
    """Whether ``artist`` (drawn in a panel) is what legend ``handle`` shows: its colour, and for lines its
    marker and line style."""
    if isinstance(handle, Line2D):
        if isinstance(artist, Line2D):
            if not _line_drawn(artist):
                return False
            same_colour = _rgba(handle.get_color()) == _rgba(artist.get_color()) or \
                (handle.get_marker() not in ("None", None, "") and
                 _rgba(handle.get_markeredgecolor()) == _rgba(artist.get_markeredgecolor()))
            hm, am = handle.get_marker(), artist.get_marker()
            hl, al = handle.get_linestyle(), artist.get_linestyle()
            marker_ok = hm in ("None", None, "") or hm == am
            style_ok = hl in ("None", "none", "") or al not in ("None", "none", "")
            # a black entry is a key to a look (line style, marker) that the coloured series share
            style_key = _rgba(handle.get_color()) == _rgba("black") and hm == am and \
                (hl in ("None", "none", "")) == (al in ("None", "none", ""))
            return (same_colour or style_key) and marker_ok and style_ok
        if isinstance(artist, Collection) and len(artist.get_offsets()):
            colours = {_rgba(c) for c in artist.get_facecolor()} | {_rgba(c) for c in artist.get_edgecolor()}
            return _rgba(handle.get_color()) in colours or _rgba(handle.get_markeredgecolor()) in colours
        return False
    if isinstance(handle, Patch):
        if isinstance(artist, Rectangle):
            return (_rgba(handle.get_facecolor()) == _rgba(artist.get_facecolor())
                    and artist.get_width() != 0 and artist.get_height() != 0)
        if isinstance(artist, Collection) and len(artist.get_paths()):
            return _rgba(handle.get_facecolor()) in {_rgba(c) for c in artist.get_facecolor()}
        return False
    if isinstance(handle, Collection):
        return isinstance(artist, Collection) and len(artist.get_offsets()) > 0 and \
            bool({_rgba(c) for c in handle.get_facecolor()} & {_rgba(c) for c in artist.get_facecolor()})
    return True  # other handle kinds: not judged


def _drawn(fig) -> list:
    out = []
    for ax in fig.axes:
        out += list(ax.lines) + list(ax.collections) + [p for p in ax.patches if isinstance(p, Rectangle)]
    return out


def legends(fig) -> list:
    return list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]


def undrawn_legend_entries(fig) -> list[str]:
    """The labels of legend entries with no drawn artist of their look in any panel."""
    drawn = _drawn(fig)
    missing = []
    for legend in legends(fig):
        for handle, text in zip(legend.legend_handles, legend.get_texts()):
            if not any(_matches(handle, artist) for artist in drawn):
                missing.append(text.get_text())
    return missing


def bad_axis_labels(fig) -> list[str]:
    """Axis labels of panels with data that lack a unit in brackets or show a raw key."""
    bad = []
    for ax in fig.axes:
        if not (ax.lines or ax.collections or ax.patches) or not ax.axison:
            continue
        for name, label, ticks in (("x", ax.get_xlabel(), ax.get_xticks()), ("y", ax.get_ylabel(), ax.get_yticks())):
            shown = [t.get_text() for t in (ax.get_xticklabels() if name == "x" else ax.get_yticklabels())]
            axis = ax.xaxis if name == "x" else ax.yaxis
            if not label and not any(t.get_visible() and t.get_text() for t in axis.get_ticklabels()) and \
                    len(axis.get_shared_axes() if hasattr(axis, "get_shared_axes") else
                        (ax.get_shared_x_axes() if name == "x" else ax.get_shared_y_axes()).get_siblings(ax)) > 1:
                continue  # an axis shared with a labelled panel, its tick labels hidden
            categorical = shown and all(t and not re.fullmatch(r"[-−+0-9.e$^{}\\mathrm]+", t) for t in shown)
            if categorical:  # names on the axis (bars): the names must not be raw keys
                bad += [f"{ax.get_title()!r} {name} tick {t!r}" for t in shown if RAW_KEY.search(t)]
                continue
            if not label and name == "x" and any(other is not ax and other.get_xlabel() and
                                                 other.get_xlim() == ax.get_xlim() for other in fig.axes):
                continue  # panels stacked on one axis: the bottom one names it
            if not label or not UNIT.search(label) or RAW_KEY.search(label):
                bad.append(f"{ax.get_title()!r} {name}: {label!r}")
    return bad


def _texts(fig) -> list:
    texts = [t for ax in fig.axes for t in ax.texts if t.get_visible() and t.get_text().strip()]
    texts += [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    return texts


def texts_over_data(fig) -> list[str]:
    """Texts and in-panel legends whose drawn extent covers data (a line's path, a marker, a bar) of the
    panel they sit in, in display coordinates."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    found = []
    for ax in fig.axes:
        items = [t for t in ax.texts if t.get_visible() and t.get_text().strip()]
        if ax.get_legend() is not None:
            items.append(ax.get_legend())
        for item in items:
            box = item.get_window_extent(renderer)
            for line in ax.lines:
                if not _line_drawn(line):
                    continue
                path = line.get_transform().transform_path(line.get_path())
                has_line = line.get_linestyle() not in ("None", "none", "", " ")
                vertices = path.vertices
                inside = np.any((vertices[:, 0] > box.x0) & (vertices[:, 0] < box.x1)
                                & (vertices[:, 1] > box.y0) & (vertices[:, 1] < box.y1))
                if inside or (has_line and path.intersects_bbox(box, filled=False)):
                    label = item.get_text() if isinstance(item, Text) else "legend"
                    found.append(f"{ax.get_title()!r}: {label[:40]!r} over {line.get_label()!r}")
                    break
            for patch in ax.patches:
                if isinstance(patch, Rectangle) and patch.get_height() != 0 and patch.get_visible():
                    if box.overlaps(patch.get_window_extent(renderer)):
                        label = item.get_text() if isinstance(item, Text) else "legend"
                        found.append(f"{ax.get_title()!r}: {label[:40]!r} over a bar")
                        break
    return found
