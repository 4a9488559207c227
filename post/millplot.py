"""Shared helpers for dem2d's mill plots (plot_series.py, report.py, sweep.py).

Reading a run's output folder:
  - read_series(path)        series.csv as {column: array}; float columns as float arrays (`nan`
                             kept), text columns (`regime`) as string arrays;
  - read_run_json(folder)    run.json as a dict ({} when absent or unreadable);
  - read_collisions(path)    collisions.csv (collision energy spectra) as a list of row dicts;
  - snapshot helpers         list_snapshots, read_snapshot, read_outline (h5py file objects).
What a mill engineer reads off it:
  - critical_speed, drum_speed, slice_thickness, mill_scaling: the 2D power is the power of a
    slice one ball diameter thick (the balls are spheres moving in a plane), so the power per
    metre of mill length is P / thickness;
  - moving_average, averaged_power: the drive power averaged in time (raw 1 ms samples spike);
  - regime_spans, dominant_regime: the charge's regime column in time.
Drawing:
  - draw_charge(ax, ...)     the particles at their true size coloured by speed, with the drum
                             and lifter outline (from the snapshot file, else from the deck);
  - particle_collections     discs as circles, superellipses as their outline polygons at their
                             angles (superellipse_outlines), for any colouring.
"""

import csv
import json
import math
import os

import numpy as np
from matplotlib.collections import EllipseCollection, LineCollection, PolyCollection

from snapshot_order import snapshot_names

REGIMES = ["slumping", "rolling", "cascading", "cataracting", "centrifuging"]
REGIME_COLORS = {
    "slumping": "tab:gray",
    "rolling": "tab:green",
    "cascading": "tab:blue",
    "cataracting": "tab:orange",
    "centrifuging": "tab:red",
    "-": "white",
}
REGIME_MARKERS = {"slumping": "v", "rolling": "s", "cascading": "o", "cataracting": "^",
                  "centrifuging": "D", "-": "x"}
UNCLASSIFIED = "-"  # series.csv's regime until the analysis window is full

RPM_PER_RAD_S = 60.0 / (2.0 * math.pi)


# --- Reading -------------------------------------------------------------------------------------

def read_series(path):
    """series.csv as {column: numpy array}: floats where every value parses (`nan` included),
    strings otherwise (the `regime` column). A truncated last row (a run killed mid-write) is
    dropped. Raises ValueError when the file is not a dem2d series."""
    with open(path, encoding="ascii", newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        rows = [row for row in reader if row]
    if not header or header[0] != "time":
        raise ValueError(f"{path}: not a dem2d series.csv (first column is not 'time')")
    rows = [row for row in rows if len(row) == len(header)]
    columns = list(zip(*rows)) if rows else [()] * len(header)
    series = {}
    for name, values in zip(header, columns):
        try:
            series[name] = np.array(values, dtype=float)
        except ValueError:
            series[name] = np.array(values, dtype=str)
    return series


def read_run_json(folder):
    """run.json in `folder` as a dict; {} when it is missing or not JSON."""
    path = os.path.join(folder, "run.json")
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def deck_of(run):
    """The resolved deck stored in run.json ({} when absent)."""
    deck = run.get("deck", {})
    return deck if isinstance(deck, dict) else {}


def run_title(run, fallback):
    """The deck's title from run.json, else `fallback`; the run's --set options after it, in
    brackets (the title is the deck's, the run may differ from it)."""
    title = deck_of(run).get("title")
    title = str(title) if title else fallback
    overrides = run.get("overrides") or []
    return f"{title} [{', '.join(map(str, overrides))}]" if overrides else title


def analysis_window(run, default=1.0):
    """output.analysis_window of the run [s] (the window of power_avg and regime)."""
    value = deck_of(run).get("output", {}).get("analysis_window", default)
    try:
        return float(value)
    except (TypeError, ValueError):
        return default


def read_collisions(path):
    """collisions.csv as a list of dicts: type (str), size_min, size_max, energy_min,
    energy_max [m, J] (float, `inf` allowed), count (int), energy [J] (float)."""
    rows = []
    with open(path, encoding="ascii", newline="") as f:
        for row in csv.DictReader(f):
            rows.append({
                "type": row["type"],
                "size_min": float(row["size_min"]),
                "size_max": float(row["size_max"]),
                "energy_min": float(row["energy_min"]),
                "energy_max": float(row["energy_max"]),
                "count": int(float(row["count"])),
                "energy": float(row["energy"]),
            })
    return rows


# --- Snapshots -----------------------------------------------------------------------------------

def list_snapshots(f):
    """Names of the complete snapshots of an open snapshots.h5, in time order (by index)."""
    return snapshot_names(f)


def read_shape(g):
    """The shape datasets of a snapshot group (scenes with superellipses) as {a, b, n, angle}
    arrays [m, m, 1, rad], or None for a snapshot without them (discs only)."""
    if "semi_axis_a" not in g:
        return None
    return {"a": np.asarray(g["semi_axis_a"][()], dtype=float),
            "b": np.asarray(g["semi_axis_b"][()], dtype=float),
            "n": np.asarray(g["exponent"][()], dtype=float),
            "angle": np.asarray(g["angle"][()], dtype=float)}


def read_snapshot(f, name):
    """One snapshot: time [s], id, position (N, 2) [m], radius [m], speed [m/s], material, and
    shape (read_shape: None without superellipses)."""
    g = f["snapshots"][name]
    position = np.asarray(g["position"][()], dtype=float).reshape(-1, 2)
    if "speed" in g:
        speed = np.asarray(g["speed"][()], dtype=float)
    else:
        v = np.asarray(g["velocity"][()], dtype=float).reshape(-1, 2)
        speed = np.hypot(v[:, 0], v[:, 1])
    return {
        "name": name,
        "time": float(g.attrs["time"]),
        "id": np.asarray(g["id"][()]),
        "position": position,
        "radius": np.asarray(g["radius"][()], dtype=float),
        "speed": speed,
        "material": np.asarray(g["material"][()]),
        "shape": read_shape(g),
    }


def read_outline(f, name):
    """The drum/lifter/wall outline of snapshot `name` as (S, 2, 2) segment ends [m], or None.
    Looks in /walls/NAME (docs/output.md) and in a `walls` group inside the snapshot."""
    candidates = []
    if "walls" in f and name in f["walls"]:
        candidates.append(f["walls"][name])
    snap = f["snapshots"][name]
    if "walls" in snap and hasattr(snap["walls"], "keys"):
        candidates.append(snap["walls"])
    for g in candidates:
        if "points" in g and "segments" in g:
            points = np.asarray(g["points"][()], dtype=float).reshape(-1, 2)
            segments = np.asarray(g["segments"][()], dtype=np.int64).reshape(-1, 2)
            return points[segments]
    return None


def max_diameter(snapshots_path):
    """The largest particle diameter of the first snapshot [m], or None."""
    try:
        import h5py  # noqa: PLC0415  (only the scripts that read snapshots need it)
        with h5py.File(snapshots_path, "r") as f:
            names = list_snapshots(f)
            if not names:
                return None
            radius = np.asarray(f["snapshots"][names[0]]["radius"][()], dtype=float)
    except (OSError, KeyError, ImportError):
        return None
    return 2.0 * float(radius.max()) if radius.size else None


# --- Mill numbers --------------------------------------------------------------------------------

def has_drum(deck, series=None):
    """True for a drum scene: the deck has a drum (or, without a deck, the series has the drum
    scenes' columns)."""
    drum = deck.get("drum") if isinstance(deck, dict) else None
    if isinstance(drum, dict) and drum:
        return bool(drum.get("radius")) and drum.get("present") is not False
    return series is not None and "power_avg" in series


def gravity_magnitude(deck):
    """|g| of the deck [m/s^2] (9.81 when not given)."""
    g = deck.get("run", {}).get("gravity", [0.0, -9.81])
    try:
        return float(math.hypot(float(g[0]), float(g[1])))
    except (TypeError, ValueError, IndexError):
        return 9.81


def critical_speed(deck):
    """The classical critical speed sqrt(|g| / R) [rad/s] of the deck's drum, or None."""
    drum = deck.get("drum", {})
    radius = drum.get("radius") if isinstance(drum, dict) else None
    g = gravity_magnitude(deck)
    if not radius or radius <= 0 or g <= 0:
        return None
    return math.sqrt(g / float(radius))


def drum_speed(deck):
    """The drum's angular speed [rad/s] from the resolved deck (speed, speed_rpm or
    critical_fraction), or None."""
    drum = deck.get("drum", {})
    if not isinstance(drum, dict):
        return None
    if drum.get("speed") is not None:
        return float(drum["speed"])
    if drum.get("speed_rpm") is not None:
        return float(drum["speed_rpm"]) / RPM_PER_RAD_S
    wc = critical_speed(deck)
    if drum.get("critical_fraction") is not None and wc:
        return float(drum["critical_fraction"]) * wc
    return None


def slice_thickness(run, snapshots_path=None):
    """(thickness [m], where it came from) of the 2D slice the power stands for: run.json's
    mill.slice_thickness_m, else the largest particle diameter of the first snapshot, else of
    the deck's fills; (None, reason) when none is known."""
    mill = run.get("mill", {})
    if isinstance(mill, dict) and mill.get("slice_thickness_m"):
        return float(mill["slice_thickness_m"]), "run.json mill.slice_thickness_m"
    if snapshots_path and os.path.exists(snapshots_path):
        d = max_diameter(snapshots_path)
        if d:
            return d, "largest particle diameter in snapshots.h5"
    radii = [float(fill["radius"]) for fill in deck_of(run).get("fill", [])
             if isinstance(fill, dict) and isinstance(fill.get("radius"), (int, float))]
    if radii:
        return 2.0 * max(radii), "largest fill diameter in the deck"
    return None, "unknown (no run.json mill object, no snapshots)"


def mill_scaling(thickness, mean_power):
    """Power per metre of mill length [W/m] for a 2D mean power [W]: mean_power / thickness
    (None when either is unknown). run.json's mill.power_per_metre_W, when the run wrote one,
    is dem2d's own figure (report.py lists it beside this one)."""
    if thickness and mean_power is not None and np.isfinite(mean_power):
        return mean_power / thickness
    return None


def slice_caption(thickness, source, mean_power=None, per_metre=None):
    """One or two lines saying what the 2D power stands for and how to scale it to a mill."""
    if not thickness:
        return ("2D model: the power is that of a slice one ball diameter thick (balls are "
                "spheres moving in a plane); slice thickness unknown, so no per-metre figure.")
    text = (f"2D model: the power is that of a slice one ball diameter thick, "
            f"d = {thickness * 1e3:.0f} mm ({source}); the balls are spheres moving in a plane.\n"
            f"Per metre of mill length: P / d")
    if per_metre is not None and mean_power is not None:
        text += (f"; mean {mean_power / 1e3:.3g} kW -> {per_metre / 1e3:.3g} kW per metre; "
                 f"a mill L m long draws about L x {per_metre / 1e3:.3g} kW")
    return text + "."


# --- Time series ---------------------------------------------------------------------------------

def moving_average(t, y, window):
    """Centred moving average of y(t) over `window` seconds (fewer samples near the ends)."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if y.size == 0 or window <= 0:
        return y.copy()
    sums = np.concatenate([[0.0], np.cumsum(y)])
    lo = np.searchsorted(t, t - 0.5 * window, side="left")
    hi = np.searchsorted(t, t + 0.5 * window, side="right")
    return (sums[hi] - sums[lo]) / np.maximum(hi - lo, 1)


def trailing_average(t, y, window):
    """Mean of y over the last `window` seconds before each t (over the rows so far while
    t < window): how series.csv's power_avg averages."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if y.size == 0 or window <= 0:
        return y.copy()
    sums = np.concatenate([[0.0], np.cumsum(y)])
    lo = np.searchsorted(t, t - window, side="right")
    hi = np.arange(1, t.size + 1)
    return (sums[hi] - sums[lo]) / np.maximum(hi - lo, 1)


def smoothed(series, run, column, window=None):
    """(column averaged in time, label): with no window, the trailing mean over the run's
    analysis window (as power_avg); with one, a centred moving average over it."""
    t = series["time"]
    if window is None:
        w = analysis_window(run)
        return trailing_average(t, series[column], w), f"mean over the last {w:g} s"
    return moving_average(t, series[column], window), f"centred moving average over {window:g} s"


def averaged_power(series, run, window=None):
    """(averaged drive power [W], label): series.csv's power_avg (the drive's mean over the
    trailing analysis window) when present and no window is asked for, else smoothed()."""
    if window is None and "power_avg" in series and series["power_avg"].dtype.kind == "f":
        w = analysis_window(run)
        return series["power_avg"], f"mean over the last {w:g} s (power_avg)"
    return smoothed(series, run, "drum_power", window)


def tail_mask(t, fraction=0.5):
    """Rows of the last `fraction` of the run's time span."""
    t = np.asarray(t, dtype=float)
    if t.size == 0:
        return np.zeros(0, dtype=bool)
    return t >= t[-1] - fraction * (t[-1] - t[0])


def mean_power(series, fraction=0.5):
    """The drive's mean power [W] over the last `fraction` of the run: the change of the drum's
    work over that span / its length (exact), else the mean of the drum_power samples."""
    t = series["time"]
    mask = tail_mask(t, fraction)
    if not mask.any():
        return float("nan")
    work = series.get("drum_work", series.get("drive_work"))
    first, last = np.argmax(mask), len(t) - 1
    if work is not None and work.dtype.kind == "f" and t[last] > t[first]:
        return float((work[last] - work[first]) / (t[last] - t[first]))
    return float(np.mean(series["drum_power"][mask]))


def power_estimate(series, speed=None, fraction=0.5, min_turns=3, blocks=8):
    """The drive's mean power over the last `fraction` of the run with its uncertainty, by batch
    means: (mean [W], standard error [W], batches, what a batch is). The span is cut into whole
    drum turns when it holds at least `min_turns` of them (the charge's motion repeats with the
    drum, so turns are the natural batches), else into `blocks` equal parts; each batch's mean
    is its change of the drum's work over its length (exact), the standard error the batch
    means' standard deviation / sqrt(batches). Consecutive batches of a tumbling charge are
    nearly independent once a batch spans a turn; shorter batches understate the error."""
    t = np.asarray(series["time"], dtype=float)
    mask = tail_mask(t, fraction)
    mean = mean_power(series, fraction)
    work = series.get("drum_work", series.get("drive_work"))
    if not mask.any() or work is None or work.dtype.kind != "f":
        return mean, float("nan"), 0, "none"
    t0, t1 = t[mask][0], t[-1]
    turn = 2.0 * np.pi / abs(speed) if speed else 0.0
    if turn > 0 and (t1 - t0) / turn >= min_turns:
        n, kind = int((t1 - t0) / turn), "drum turns"
        edges = t1 - turn * np.arange(n, -1, -1)
    else:
        n, kind = blocks, "equal parts"
        edges = np.linspace(t0, t1, blocks + 1)
    w = np.interp(edges, t, work)  # the work at the batch edges (rows fall on them or close)
    means = np.diff(w) / np.diff(edges)
    if n < 2:
        return mean, float("nan"), n, kind
    return mean, float(np.std(means, ddof=1) / np.sqrt(n)), n, kind


def regime_column(series):
    """The regime column as strings ('-' everywhere when the series has none)."""
    r = series.get("regime")
    if r is None or r.dtype.kind not in "US":
        return np.full(len(series["time"]), UNCLASSIFIED)
    return r


def regime_spans(t, regime):
    """[(t_start, t_end, regime)] of the runs of equal regime values."""
    spans = []
    start = 0
    for i in range(1, len(regime) + 1):
        if i == len(regime) or regime[i] != regime[start]:
            end = t[i] if i < len(regime) else t[-1]
            spans.append((float(t[start]), float(end), str(regime[start])))
            start = i
    return spans


def dominant_regime(series, fraction=0.5):
    """The most frequent classified regime over the last `fraction` of the run ('-': none)."""
    regime = regime_column(series)[tail_mask(series["time"], fraction)]
    regime = regime[regime != UNCLASSIFIED]
    if regime.size == 0:
        return UNCLASSIFIED
    names, counts = np.unique(regime, return_counts=True)
    return str(names[np.argmax(counts)])


def regime_at(series, time):
    """The regime in the series row nearest to `time` ('-' when unclassified)."""
    t = series["time"]
    if len(t) == 0:
        return UNCLASSIFIED
    return str(regime_column(series)[int(np.argmin(np.abs(t - time)))])


# --- Drawing -------------------------------------------------------------------------------------

def drum_angle(drum, t):
    """The drum's angle [rad] at time t: its start angle plus the integral of the speed, which
    rises linearly from 0 over ramp_time."""
    w = drum_speed({"drum": drum}) or 0.0
    ramp = float(drum.get("ramp_time", 0.0) or 0.0)
    if ramp <= 0.0:
        turned = w * t
    elif t < ramp:
        turned = 0.5 * w * t * t / ramp
    else:
        turned = w * (t - 0.5 * ramp)
    return math.radians(float(drum.get("angle", 0.0) or 0.0)) + turned


def deck_outline(deck, t):
    """The drum (circle or polygon) and its lifters (three sides each) at time t as segment ends
    (S, 2, 2) [m], from the resolved deck; None when the deck has no drum. A fallback for
    snapshot files without an outline."""
    drum = deck.get("drum", {})
    if not isinstance(drum, dict) or not drum.get("radius") or drum.get("present") is False:
        return None
    radius = float(drum["radius"])
    cx, cy = (float(c) for c in drum.get("center", [0.0, 0.0]))
    phi = drum_angle(drum, t)
    sides = int(drum.get("sides", 0) or 0)
    n = sides if sides >= 3 else 256
    a = phi + 2.0 * math.pi * np.arange(n + 1) / n
    ring = np.column_stack([cx + radius * np.cos(a), cy + radius * np.sin(a)])
    segments = [np.stack([ring[:-1], ring[1:]], axis=1)]
    inner = radius if sides < 3 else radius * math.cos(math.pi / sides)
    for lifter in drum.get("lifter", []):
        h, w = float(lifter["height"]), float(lifter["width"])
        foot = math.sqrt(max(inner * inner - 0.25 * w * w, 0.0))
        count = int(lifter["count"])
        for k in range(count):
            b = phi + math.radians(float(lifter.get("angle", 0.0))) + 2.0 * math.pi * k / count
            out, side = np.array([math.cos(b), math.sin(b)]), np.array([-math.sin(b), math.cos(b)])
            pts = np.array([foot * out - 0.5 * w * side, (inner - h) * out - 0.5 * w * side,
                            (inner - h) * out + 0.5 * w * side, foot * out + 0.5 * w * side])
            pts += np.array([cx, cy])
            segments.append(np.stack([pts[:-1], pts[1:]], axis=1))
    return np.concatenate(segments)


def charge_limits(deck, snap, outline):
    """(xlim, ylim) that show the drum (or the particles and walls) with a small margin."""
    drum = deck.get("drum", {})
    if isinstance(drum, dict) and drum.get("radius"):
        r = float(drum["radius"])
        cx, cy = (float(c) for c in drum.get("center", [0.0, 0.0]))
        lo, hi = np.array([cx - r, cy - r]), np.array([cx + r, cy + r])
    else:
        half = snap["radius"][:, None]
        pts = [snap["position"] - half, snap["position"] + half]
        if outline is not None:
            pts.append(outline.reshape(-1, 2))
        allpts = np.concatenate(pts) if pts else np.zeros((1, 2))
        lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    margin = 0.04 * float(max(hi - lo)) if np.all(hi > lo) else 1.0
    return (lo[0] - margin, hi[0] + margin), (lo[1] - margin, hi[1] + margin)


# Points of each superellipse's drawn outline (a multiple of 4): the polygon's area is within
# 0.2 % of the curve's (an ellipse: (K / 2 pi) sin(2 pi / K) = 0.9984 of it).
OUTLINE_VERTICES = 64


def superellipse_outlines(a, b, n, angle, position, vertices=OUTLINE_VERTICES):
    """(M, K, 2) outline points [m] of M superellipses |x/a|^n + |y/b|^n = 1 turned by `angle`
    about their centres `position` (M, 2): the parametric form x = a sgn(cos t)|cos t|^(2/n),
    y = b sgn(sin t)|sin t|^(2/n) at t = 2 pi k / K, counter-clockwise, as snapshots.h5's
    /outlines (core/shape/outline.hpp). cos t and sin t at the quarter turns are exact (0, +-1),
    so the points there lie on the axes for any n."""
    a, b, n, angle = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (a, b, n, angle))
    position = np.asarray(position, dtype=float).reshape(-1, 2)
    quarter = vertices // 4
    q, r = np.divmod(np.arange(4 * quarter), quarter)
    phi = 2.0 * np.pi * r / (4 * quarter)
    c0, s0 = np.where(r == 0, 1.0, np.cos(phi)), np.where(r == 0, 0.0, np.sin(phi))
    c = np.choose(q, [c0, -s0, -c0, s0])
    s = np.choose(q, [s0, c0, -s0, -c0])
    power = (2.0 / n)[:, None]
    x = a[:, None] * np.sign(c) * np.abs(c) ** power
    y = b[:, None] * np.sign(s) * np.abs(s) ** power
    ca, sa = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return np.stack([position[:, :1] + ca * x - sa * y, position[:, 1:] + sa * x + ca * y], axis=-1)


def shaped_rows(snap):
    """Indices of the snapshot's particles that are not discs (a != b or n != 2)."""
    shape = snap.get("shape")
    if shape is None:
        return np.zeros(0, dtype=np.int64)
    return np.flatnonzero((shape["a"] != shape["b"]) | (shape["n"] != 2.0))


def particle_collections(ax, snap, values=None, cmap="viridis", clim=(0.0, 1.0), facecolors=None,
                         edgecolors="0.2", linewidths=0.2):
    """The particles at their true size: discs as circles (an EllipseCollection in data units,
    first, always there), superellipses as their outline polygons at their angles (a
    PolyCollection, only when the snapshot has some). Coloured by `values` through cmap and
    clim, or with `facecolors` (one per particle). Added to ax and returned as a list (the
    first for a colorbar); each collection's `rows` are the snapshot rows it draws."""
    shaped = shaped_rows(snap)
    discs = np.setdiff1d(np.arange(len(snap["radius"])), shaped)
    r = snap["radius"][discs]
    kwargs = dict(widths=2 * r, heights=2 * r, angles=np.zeros_like(r), units="xy",
                  offsets=snap["position"][discs].reshape(-1, 2), edgecolors=edgecolors,
                  linewidths=linewidths)
    try:
        circles = EllipseCollection(offset_transform=ax.transData, **kwargs)
    except TypeError:  # matplotlib < 3.6
        circles = EllipseCollection(transOffset=ax.transData, **kwargs)
    circles.rows = discs
    out = [circles]
    if shaped.size:
        shape = snap["shape"]
        verts = superellipse_outlines(shape["a"][shaped], shape["b"][shaped], shape["n"][shaped],
                                      shape["angle"][shaped], snap["position"][shaped])
        polygons = PolyCollection(verts, closed=True, edgecolors=edgecolors, linewidths=linewidths)
        polygons.rows = shaped
        out.append(polygons)
    for c in out:
        if facecolors is not None:
            c.set_facecolor([facecolors[i] for i in c.rows])
        else:
            c.set_array(np.asarray(values)[c.rows])
            c.set_cmap(cmap)
            c.set_clim(*clim)
        ax.add_collection(c)
    return out


def particle_collection(ax, snap, vmax, cmap="viridis"):
    """The particles at their true size coloured by speed (particle_collections); added to ax.
    Returns the list of collections (the first for a colorbar)."""
    return particle_collections(ax, snap, snap["speed"], cmap, (0.0, vmax if vmax > 0 else 1.0))


def draw_charge(ax, snap, outline, deck, vmax):
    """Particles coloured by speed with the drum/lifter outline (segments (S, 2, 2); when None,
    built from the deck at the snapshot's time). Returns the particles' collection."""
    if outline is None:
        outline = deck_outline(deck, snap["time"])
    circles = particle_collection(ax, snap, vmax)[0]
    if outline is not None and len(outline):
        ax.add_collection(LineCollection(outline, colors="0.15", linewidths=1.5))
    xlim, ylim = charge_limits(deck, snap, outline)
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return circles
