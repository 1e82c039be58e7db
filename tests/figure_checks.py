"""What a reader needs from a figure, read back from matplotlib's own artists and extents.

- every legend entry stands for something drawn (:func:`undrawn_legend_entries`);
- every axis label of a panel with data names a unit in brackets and holds no raw key such as
  ``steady_speed_m_s`` (:func:`bad_axis_labels`);
- no text (annotation, note, legend inside a panel) lies over data: a line's path, a bar or an error bar, in
  display coordinates after drawing (:func:`texts_over_data`), nor runs over its panel's edge
  (:func:`texts_beyond_panel`);
- a legend entry is visible: a handle of another colour than the legend's own background, and where it stands
  for a band or a bar, one drawn at least :data:`MIN_PX` wide (:func:`undrawn_legend_entries`);
- no text anywhere in the figure shows a code name (``travel_m``, ``first-order-kinematics``, ``|cost|``,
  ``S_dot``, ``lambda1``, a variant's key) where words belong (:func:`raw_names`);
- a colour bar's tick labels are plain numbers, at least two of them (:func:`unreadable_colour_bars`).
"""

from __future__ import annotations

import re

import matplotlib.colors as mcolors
import numpy as np
from matplotlib.collections import Collection, LineCollection
from matplotlib.container import ErrorbarContainer
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


MIN_PX = 2.0  # display pixels: a band or a bar narrower than this does not show as one
CONTRAST = 0.2  # RGB distance (0..sqrt(3)) below which a handle's colour does not show on its legend's background


def _wide_enough(artist, renderer) -> bool:
    box = artist.get_window_extent(renderer)
    return box.width >= MIN_PX and box.height >= MIN_PX


def _dashes(line: Line2D) -> tuple:
    """A line's dash pattern as drawn: (offset, (on, off, ...)) in points, rounded."""
    offset, sequence = line._dash_pattern  # matplotlib's scaled pattern (no public getter)
    return round(offset or 0.0, 2), tuple(round(v, 2) for v in (sequence or ()))


def _matches(handle, artist, renderer=None) -> bool:
    """Whether ``artist`` (drawn in a panel) is what legend ``handle`` shows: its colour, and for lines its
    marker and line style; a patch's artist at least :data:`MIN_PX` wide and high where ``renderer`` is given."""
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
            # a black entry is a key to a look (line style, marker) that the coloured series share: the same
            # dashes (offset and lengths as drawn, in points), so that a black dotted key does not stand for
            # coloured lines whose dashes fill each other's gaps
            style_key = _rgba(handle.get_color()) == _rgba("black") and hm == am and \
                (hl in ("None", "none", "")) == (al in ("None", "none", "")) and \
                (hl in ("None", "none", "") or _dashes(handle) == _dashes(artist))
            return (same_colour or style_key) and marker_ok and style_ok
        if isinstance(artist, Collection) and len(artist.get_offsets()):
            colours = {_rgba(c) for c in artist.get_facecolor()} | {_rgba(c) for c in artist.get_edgecolor()}
            return _rgba(handle.get_color()) in colours or _rgba(handle.get_markeredgecolor()) in colours
        if isinstance(artist, Collection) and len(artist.get_paths()) and handle.get_marker() in ("None", None, ""):
            # a contour or a set of line segments drawn in the handle's colour
            return _rgba(handle.get_color()) in {_rgba(c) for c in artist.get_edgecolor()} and \
                (renderer is None or _wide_enough(artist, renderer))
        return False
    if isinstance(handle, Patch):
        if not handle.get_fill() or _rgba(handle.get_facecolor())[3] == 0:  # an outline (a step histogram)
            return isinstance(artist, Patch) and _rgba(handle.get_edgecolor()) == _rgba(artist.get_edgecolor()) \
                and (renderer is None or _wide_enough(artist, renderer))
        if isinstance(artist, Rectangle):
            return (_rgba(handle.get_facecolor()) == _rgba(artist.get_facecolor())
                    and artist.get_width() != 0 and artist.get_height() != 0
                    and (renderer is None or _wide_enough(artist, renderer)))
        if isinstance(artist, Collection) and len(artist.get_paths()):
            return _rgba(handle.get_facecolor()) in {_rgba(c) for c in artist.get_facecolor()} and \
                (renderer is None or _wide_enough(artist, renderer))
        return False
    if isinstance(handle, LineCollection):  # an error bar's key: its lines in its colour
        return isinstance(artist, LineCollection) and len(artist.get_paths()) > 0 and \
            bool({_rgba(c) for c in handle.get_color()} & {_rgba(c) for c in artist.get_color()})
    if isinstance(handle, Collection):
        return isinstance(artist, Collection) and len(artist.get_offsets()) > 0 and \
            bool({_rgba(c) for c in handle.get_facecolor()} & {_rgba(c) for c in artist.get_facecolor()})
    return True  # other handle kinds: not judged


def _drawn(fig) -> list:
    out = []
    for ax in fig.axes:
        out += list(ax.lines) + list(ax.collections) + [p for p in ax.patches if p.get_visible()]
    return out


def legends(fig) -> list:
    return list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]


def _over(colour, background) -> np.ndarray:
    """``colour`` (RGBA) as it shows over an opaque ``background`` (RGB)."""
    rgba = np.asarray(mcolors.to_rgba(colour))
    return rgba[3] * rgba[:3] + (1 - rgba[3]) * np.asarray(background)


def _handle_colours(handle) -> list:
    """The colours a legend handle is drawn in (a line's colour, its markers' face and edge, a patch's face and
    edge, a stroke around it), skipping 'none'."""
    if isinstance(handle, Line2D):
        colours = [handle.get_color()] if handle.get_linestyle() not in ("None", "none", "", " ") else []
        if handle.get_marker() not in ("None", None, "", " "):
            colours += [handle.get_markerfacecolor(), handle.get_markeredgecolor()]
    elif isinstance(handle, Patch):
        colours = [handle.get_facecolor()] + ([handle.get_edgecolor()] if handle.get_linewidth() else [])
    else:
        return []
    for effect in handle.get_path_effects() or ():
        colour = getattr(effect, "_gc", {}).get("foreground")
        if colour is not None:
            colours.append(colour)
    return [c for c in colours if _rgba(c) is not None and (not isinstance(c, str) or c != "none")]


def _invisible(handle, legend) -> bool:
    """Whether every colour ``handle`` is drawn in is within :data:`CONTRAST` of its legend's background."""
    colours = _handle_colours(handle)
    if not colours:
        return False  # not judged
    frame = legend.get_frame()
    background = _over(frame.get_facecolor(), (1.0, 1.0, 1.0)) if frame.get_visible() else np.ones(3)
    return all(np.linalg.norm(_over(c, background) - background) < CONTRAST for c in colours)


def undrawn_legend_entries(fig) -> list[str]:
    """The labels of legend entries with no drawn artist of their look in any panel (a band or a bar
    narrower than :data:`MIN_PX` counts as not drawn), or drawn in the legend's own background colour."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    drawn = _drawn(fig)
    missing = []
    for legend in legends(fig):
        for handle, text in zip(legend.legend_handles, legend.get_texts()):
            if not any(_matches(handle, artist, renderer) for artist in drawn) or _invisible(handle, legend):
                missing.append(text.get_text())
    return missing


def unexplained_lines(fig) -> list[str]:
    """In a figure with a legend: the lines and markers drawn whose look (colour, and marker or line style)
    no legend entry gives, e.g. a black zero line or an orange marker of a colour the legend does not name.
    A colour counts as named where an entry has it; a black or grey entry keys a look in any named colour."""
    handles = [h for legend in legends(fig) for h in legend.legend_handles if isinstance(h, Line2D)]
    if not legends(fig):
        return []
    named = {_rgba(c) for legend in legends(fig) for h in legend.legend_handles for c in _handle_colours(h)}
    found = []
    for ax in fig.axes:
        # not series: error bars (their meaning is the axis's or the caption's) and the base line of a bar chart
        errorbars = {id(a) for c in ax.containers if isinstance(c, ErrorbarContainer) for a in c.get_children()}
        bars = any(isinstance(p, Rectangle) and p.get_width() and p.get_height() for p in ax.patches)
        for line in ax.lines:
            if not _line_drawn(line) or id(line) in errorbars:
                continue
            if bars and (set(np.asarray(line.get_xdata(), float)) == {0.0} or
                         set(np.asarray(line.get_ydata(), float)) == {0.0}):
                continue
            colour = _rgba(line.get_color()) if line.get_linestyle() not in ("None", "none", "", " ") \
                else _rgba(line.get_markeredgecolor())
            if colour in named and any(_matches(h, line) for h in handles):
                continue
            found.append(f"{ax.get_title()[:40]!r}: {line.get_label()!r} ({mcolors.to_hex(colour)}, "
                         f"{line.get_linestyle()}, marker {line.get_marker()})")
    return found


def bad_axis_labels(fig) -> list[str]:
    """Axis labels of panels with data that lack a unit in brackets or show a raw key."""
    bad = []
    for ax in fig.axes:
        colorbar = getattr(ax, "_colorbar", None)
        if colorbar is not None:  # a colour bar: its long axis names the colours
            label = colorbar.long_axis.get_label_text()
            if not UNIT.search(label) or RAW_KEY.search(label):
                bad.append(f"colour bar: {label!r}")
            continue
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
            # a text's own extent: an annotation's leader line to its point may cross data
            box = Text.get_window_extent(item, renderer) if isinstance(item, Text) else item.get_window_extent(renderer)
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
            for collection in ax.collections:  # error bars' lines (LineCollection)
                if not isinstance(collection, LineCollection) or not collection.get_visible():
                    continue
                transform = collection.get_transform()
                if any(transform.transform_path(path).intersects_bbox(box, filled=False)
                       for path in collection.get_paths()):
                    label = item.get_text() if isinstance(item, Text) else "legend"
                    found.append(f"{ax.get_title()!r}: {label[:40]!r} over an error bar")
                    break
    return found


def texts_beyond_panel(fig) -> list[str]:
    """Texts in a panel (annotations, notes) whose drawn extent runs over the panel's edge, and figure-level
    texts and legends beyond the figure's."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    found = []
    for ax in fig.axes:
        frame = ax.get_window_extent(renderer)
        for text in ax.texts:
            if not (text.get_visible() and text.get_text().strip()):
                continue
            box = Text.get_window_extent(text, renderer)
            if box.x0 < frame.x0 - 1 or box.x1 > frame.x1 + 1 or box.y0 < frame.y0 - 1 or box.y1 > frame.y1 + 1:
                found.append(f"{ax.get_title()!r}: {text.get_text()[:40]!r} over the panel's edge")
    page = fig.bbox
    titles = [t for ax in fig.axes for t in (ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label)
              if t.get_visible() and t.get_text().strip()]
    for item in [t for t in fig.texts if t.get_visible() and t.get_text().strip()] + titles + legends(fig):
        box = item.get_window_extent(renderer)
        if box.x0 < page.x0 - 1 or box.x1 > page.x1 + 1 or box.y0 < page.y0 - 1 or box.y1 > page.y1 + 1:
            found.append(f"{item.get_text()[:40] if isinstance(item, Text) else 'legend'!r} beyond the figure")
    return found


def _raw_patterns() -> re.Pattern:
    """Code names a reader should not meet in a figure: snake_case keys other than the parameters' names
    (which users type: ``M_stall``, ``mu_wall``), ``S_dot``, ``lambda1``/``lambda2``, ``|cost|``, the atlas's
    idealization names and the registry's variant names."""
    from ipir_mujoco.core.params import describe_parameters
    from ipir_mujoco.registry import ALIASES, NAMES
    from ipir_mujoco.studies.atlas_space import NAMES as IDEALIZATIONS

    hyphenated = sorted(set(NAMES) | set(ALIASES) | set(IDEALIZATIONS), key=len, reverse=True)
    parameters = "|".join(re.escape(row["name"]) for row in describe_parameters())
    return re.compile("|".join([
        rf"\b(?!(?:{parameters})\b)[a-z][a-z0-9]*(?:_[a-z0-9]+)+\b",  # travel_m, energy_per_metre_j_m
        r"\bS_dot\b", r"\blambda[12]\b", r"\|cost\|",
        *(rf"(?<![\w-]){re.escape(name)}(?![\w-])" for name in hyphenated)]))


def _in_view(value: float, view) -> bool:
    low, high = sorted(view)
    margin = 1e-9 * (abs(low) + abs(high))
    return low - margin <= value <= high + margin


def _shown_texts(fig) -> list[Text]:
    """Every text of the figure a reader sees: titles, labels, tick labels inside their axis' view, legends'
    entries and titles, annotations, the figure's own texts."""
    fig.canvas.draw()
    ticks = {}  # tick label -> (its coordinate along its axis, the axis' view)
    for ax in fig.axes:
        for axis, k in ((ax.xaxis, 0), (ax.yaxis, 1)):
            for label in axis.get_ticklabels(which="both"):
                ticks[id(label)] = (label.get_position()[k], axis.get_view_interval())
    texts = []
    for item in fig.findobj(Text):
        if not item.get_visible() or not item.get_text().strip():
            continue
        if id(item) in ticks and not _in_view(*ticks[id(item)]):
            continue
        texts.append(item)
    return texts


def raw_names(fig) -> list[str]:
    """Every shown text holding a code name where words belong (:func:`_raw_patterns`)."""
    pattern = _raw_patterns()
    return [text.get_text() for text in _shown_texts(fig) if pattern.search(text.get_text())]


def unreadable_colour_bars(fig) -> list[str]:
    """Colour bars whose tick labels are not plain numbers ('$\\mathdefault{2\\times10^{1}}$' reads as
    '2x10^1'), or which show fewer than two."""
    fig.canvas.draw()
    bad = []
    for ax in fig.axes:
        colorbar = getattr(ax, "_colorbar", None)
        if colorbar is None:
            continue
        axis = colorbar.long_axis
        k = 1 if axis is ax.yaxis else 0
        shown = [t.get_text() for t in axis.get_ticklabels(which="both")
                 if t.get_visible() and t.get_text() and _in_view(t.get_position()[k], axis.get_view_interval())]
        odd = [t for t in shown if not re.fullmatch(r"[-\u2212]?[0-9]+(\.[0-9]+)?", t)]
        if odd or len(shown) < 2:
            bad.append(f"{ax.get_ylabel() or ax.get_xlabel()!r}: ticks {shown}")
    return bad


def overlapping_labels(fig) -> list[str]:
    """Titles, axis labels and the figure's title that run into one another (three panels' long titles did)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    items = [t for ax in fig.axes for t in (ax.title, ax._left_title, ax._right_title, ax.xaxis.label,
                                            ax.yaxis.label)]
    items += [t for t in fig.texts] + ([fig._suptitle] if fig._suptitle is not None else [])
    items = list({id(t): t for t in items if t.get_visible() and t.get_text().strip()}.values()) + legends(fig)
    boxes = [(t, t.get_window_extent(renderer)) for t in items]

    def name(item) -> str:
        return repr(item.get_text()[:30]) if isinstance(item, Text) else "a legend"
    found = [f"{name(a)} over {name(b)}" for i, (a, box_a) in enumerate(boxes) for b, box_b in boxes[i + 1:]
             if box_a.overlaps(box_b)]
    # a legend placed outside its panel must not lie on another panel
    for legend in legends(fig):
        box = legend.get_window_extent(renderer)
        for ax in fig.axes:
            if ax is not legend.axes and ax.get_visible() and box.overlaps(ax.get_window_extent(renderer)):
                found.append(f"a legend over the panel {ax.get_title()[:30]!r}")
    return found


def faults(fig) -> dict[str, list[str]]:
    """Every check of this module on ``fig``: {check: what it found}, empty lists where a figure reads right."""
    return {"undrawn legend entries": undrawn_legend_entries(fig), "lines not in the legend": unexplained_lines(fig),
            "axis labels": bad_axis_labels(fig),
            "texts over data": texts_over_data(fig), "texts beyond the panel": texts_beyond_panel(fig),
            "labels over labels": overlapping_labels(fig),
            "raw names": raw_names(fig), "colour bars": unreadable_colour_bars(fig)}


def assert_reads_right(fig) -> None:
    """Fail with every fault :func:`faults` finds."""
    found = {check: items for check, items in faults(fig).items() if items}
    assert not found, found
