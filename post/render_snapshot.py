#!/usr/bin/python3
"""Draw the particles of a dem2d snapshots.h5 at their true size, coloured by material or speed.

    post/render_snapshot.py OUT/snapshots.h5                   # last snapshot -> PNG
    post/render_snapshot.py OUT/snapshots.h5 --index 0 --color speed -o first.png
    post/render_snapshot.py OUT/snapshots.h5 --all -o frames/  # every snapshot, one PNG each
    post/render_snapshot.py OUT/snapshots.h5 --list            # what the file holds
    post/render_snapshot.py OUT/snapshots.h5 --json drawn.json # also: what was drawn

The drum is drawn when its radius is known: from --drum-radius / --drum-center, or else from
run.json beside the HDF5 file ({"deck": {"drum": {"radius": R, "center": [x, y]}}}).
Particles are drawn at their true size (in data units), so a packing looks like a packing:
discs as circles of their radius, superellipses (snapshots with semi_axis_a, semi_axis_b and
exponent) as their outline polygons (64 points on the curve) turned by their angle. A run with
a [shell] also has the shell's finite elements in its snapshots (/shell, /shell_mesh): the
shell ring and lifter bars are drawn as the mesh's quadrilaterals, at rest, coloured by their
nodes' mean von Mises stress. --json writes, for the picture drawn, each circle (id, centre,
radius) and each outline polygon (id and its vertices as drawn), and the number of shell cells
drawn, so that a test can measure them.
"""

import argparse
import json
import math
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import EllipseCollection, PolyCollection  # noqa: E402
from matplotlib.patches import Circle, Patch  # noqa: E402

import millplot  # noqa: E402
from snapshot_order import snapshot_names  # noqa: E402


def material_names(f):
    if "materials/name" not in f:
        return []
    return [n.decode() if isinstance(n, bytes) else str(n) for n in f["materials/name"][()]]


def read_snapshot(f, name):
    g = f["snapshots"][name]
    return {
        "name": name,
        "time": float(g.attrs["time"]),
        "step": int(g.attrs["step"]),
        "id": np.asarray(g["id"][()]),
        "position": np.asarray(g["position"][()]).reshape(-1, 2),
        "velocity": np.asarray(g["velocity"][()]).reshape(-1, 2),
        "radius": np.asarray(g["radius"][()]),
        "material": np.asarray(g["material"][()]),
        "shape": millplot.read_shape(g),
        "shell": read_shell(f, name),
    }


def read_shell(f, name):
    """The shell of snapshot `name` (runs with a [shell]): its nodes, von Mises stress and the
    mesh's quadrilaterals; None without one."""
    if "shell" not in f or name not in f["shell"] or "shell_mesh" not in f:
        return None
    g = f["shell"][name]
    return {"points": np.asarray(g["points"][()]), "von_mises": np.asarray(g["von_mises"][()]),
            "quadrilaterals": np.asarray(f["shell_mesh/quadrilaterals"][()])}


def drum_geometry(args):
    """(radius, (cx, cy)) of the drum, or None."""
    if args.drum_radius is not None:
        return args.drum_radius, tuple(args.drum_center or (0.0, 0.0)), None
    run_json = args.run_json or os.path.join(os.path.dirname(os.path.abspath(args.snapshots)),
                                             "run.json")
    if not os.path.exists(run_json):
        return None
    try:
        with open(run_json, encoding="utf-8") as fh:
            drum = json.load(fh).get("deck", {}).get("drum", {})
    except (OSError, ValueError) as e:
        print(f"render_snapshot.py: ignoring {run_json}: {e}", file=sys.stderr)
        return None
    radius = drum.get("radius") if isinstance(drum, dict) else None
    if not radius or radius <= 0 or drum.get("present") is False:
        return None
    center = drum.get("center", [0.0, 0.0])
    if args.drum_center:
        center = args.drum_center
    shell = {"sides": int(drum.get("sides", 0)), "speed": float(drum.get("speed", 0.0)),
             "ramp_time": float(drum.get("ramp_time", 0.0)),
             "angle": math.radians(float(drum.get("angle", 0.0))),
             "lifters": [dict(l) for l in drum.get("lifter", [])]}
    return float(radius), (float(center[0]), float(center[1])), shell


def drum_angle(shell, t):
    """Drum angle at time t: linear speed ramp from 0 over ramp_time (docs/models.md)."""
    w, ramp = shell["speed"], shell["ramp_time"]
    if ramp <= 0.0:
        turned = w * t
    elif t < ramp:
        turned = 0.5 * w * t * t / ramp
    else:
        turned = w * (t - 0.5 * ramp)
    return shell["angle"] + turned


def shell_outlines(radius, center, shell, t):
    """Polylines of the drum's shell (polygon sides) and lifters at time t, in the lab frame."""
    phi = drum_angle(shell, t)
    cx, cy = center
    lines = []
    n = shell["sides"]
    if n >= 3:
        a = phi + 2 * math.pi * np.arange(n + 1) / n
        lines.append(np.column_stack([cx + radius * np.cos(a), cy + radius * np.sin(a)]))
    inner = radius if n < 3 else radius * math.cos(math.pi / n)
    for lifter in shell["lifters"]:
        h, w = float(lifter["height"]), float(lifter["width"])
        foot = math.sqrt(max(radius * radius - 0.25 * w * w, 0.0))
        for k in range(int(lifter["count"])):
            b = phi + math.radians(float(lifter.get("angle", 0.0))) + 2 * math.pi * k / int(lifter["count"])
            rad, side = np.array([math.cos(b), math.sin(b)]), np.array([-math.sin(b), math.cos(b)])
            pts = [foot * rad - 0.5 * w * side, (inner - h) * rad - 0.5 * w * side,
                   (inner - h) * rad + 0.5 * w * side, foot * rad + 0.5 * w * side]
            lines.append(np.array(pts) + np.array(center))
    return lines


def drawn_shapes(snap, collections):
    """What the picture shows of each particle: {"circles": [{id, centre, radius}],
    "outlines": [{id, vertices}]} (the vertices as the PolyCollection holds them, data units)."""
    circles, outlines = [], []
    for c in collections:
        if isinstance(c, EllipseCollection):  # the discs, drawn at their radius
            for i, row in enumerate(c.rows):
                circles.append({"id": int(snap["id"][row]),
                                "centre": [float(v) for v in snap["position"][row]],
                                "radius": float(snap["radius"][row])})
        else:
            for row, path in zip(c.rows, c.get_paths()):
                verts = path.vertices
                if len(verts) > 1 and np.array_equal(verts[0], verts[-1]):
                    verts = verts[:-1]  # the closing point
                outlines.append({"id": int(snap["id"][row]), "vertices": verts.tolist()})
    return {"snapshot": snap["name"], "circles": circles, "outlines": outlines}


def render(snap, materials, drum, color, speed_max, out, size, dpi, drawn=None):
    pos, r = snap["position"], snap["radius"]
    fig, ax = plt.subplots(figsize=(size, size), constrained_layout=True)
    ax.set_aspect("equal")
    if drum is not None:
        radius, center, shell = drum
        if shell is None or shell["sides"] < 3:
            ax.add_patch(Circle(center, radius, fill=False, color="0.3", linewidth=1.5))
        if shell is not None:
            for line in shell_outlines(radius, center, shell, float(snap["time"])):
                ax.plot(line[:, 0], line[:, 1], color="0.3", linewidth=1.5)
        margin = 0.05 * radius
        ax.set_xlim(center[0] - radius - margin, center[0] + radius + margin)
        ax.set_ylim(center[1] - radius - margin, center[1] + radius + margin)
    elif snap["shell"] is not None:
        lo, hi = snap["shell"]["points"].min(axis=0), snap["shell"]["points"].max(axis=0)
        margin = 0.05 * float((hi - lo).max())
        ax.set_xlim(lo[0] - margin, hi[0] + margin)
        ax.set_ylim(lo[1] - margin, hi[1] + margin)
    elif len(r):  # radius: the bounding circle of a superellipse
        lo = (pos - r[:, None]).min(axis=0)
        hi = (pos + r[:, None]).max(axis=0)
        margin = 0.05 * max(hi[0] - lo[0], hi[1] - lo[1], 2 * float(r.max()))
        ax.set_xlim(lo[0] - margin, hi[0] + margin)
        ax.set_ylim(lo[1] - margin, hi[1] + margin)

    shell_cells = 0
    if snap["shell"] is not None:
        sh = snap["shell"]
        if drum is not None:  # the drum's circle is the shell's inner surface: room for its outside
            x0, x1 = ax.get_xlim()
            y0, y1 = ax.get_ylim()
            lo, hi = sh["points"].min(axis=0), sh["points"].max(axis=0)
            pad = 0.02 * (x1 - x0)
            ax.set_xlim(min(x0, lo[0] - pad), max(x1, hi[0] + pad))
            ax.set_ylim(min(y0, lo[1] - pad), max(y1, hi[1] + pad))
        quads = sh["quadrilaterals"]
        cells = PolyCollection(sh["points"][quads], array=sh["von_mises"][quads].mean(axis=1) / 1e6,
                               cmap="inferno", edgecolors="none", zorder=0)
        ax.add_collection(cells)
        fig.colorbar(cells, ax=ax, shrink=0.8, label="shell: von Mises [MPa]")
        shell_cells = len(quads)
    if len(r):
        style = dict(edgecolors="0.15", linewidths=0.3)
        if color == "speed":
            speed = np.hypot(snap["velocity"][:, 0], snap["velocity"][:, 1])
            drawn_collections = millplot.particle_collections(
                ax, snap, speed, "viridis", (0.0, speed_max if speed_max > 0 else 1.0), **style)
            fig.colorbar(drawn_collections[0], ax=ax, shrink=0.8, label="speed [m/s]")
        else:
            cmap = plt.get_cmap("tab10")
            mat = snap["material"].astype(int)
            drawn_collections = millplot.particle_collections(
                ax, snap, facecolors=[cmap(m % 10) for m in mat], **style)
            used = sorted(set(mat.tolist()))
            labels = [materials[m] if 0 <= m < len(materials) else f"material {m}" for m in used]
            ax.legend(handles=[Patch(color=cmap(m % 10), label=lab) for m, lab in zip(used, labels)],
                      loc="upper right", fontsize="small")
    ax.set_title(f"snapshot {snap['name']}   t = {snap['time']:.6g} s   step {snap['step']}"
                 f"   {len(r)} particles")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    fig.savefig(out, dpi=dpi)
    plt.close(fig)
    if drawn is not None:
        drawn.append(drawn_shapes(snap, drawn_collections if len(r) else []))
        drawn[-1]["shell_cells"] = shell_cells


def write_drawn(path, drawn):
    """--json: the list of drawn_shapes, one per picture."""
    if path:
        with open(path, "w", encoding="utf-8") as fh:
            json.dump(drawn, fh)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("snapshots", help="snapshots.h5 written by dem2d")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--index", type=int, default=-1,
                       help="snapshot to draw, 0-based; negative counts from the end (default -1)")
    which.add_argument("--all", action="store_true", help="draw every snapshot as a frame")
    which.add_argument("--list", action="store_true", help="list the snapshots and exit")
    parser.add_argument("--color", choices=["material", "speed"], default="material")
    parser.add_argument("--drum-radius", type=float, help="drum radius [m] (default: run.json)")
    parser.add_argument("--drum-center", type=float, nargs=2, metavar=("X", "Y"),
                        help="drum centre [m] (default: run.json, or 0 0)")
    parser.add_argument("--run-json", help="run.json to read the drum from "
                        "(default: run.json beside the HDF5 file)")
    parser.add_argument("-o", "--output",
                        help="PNG to write (default: snapshot_NNNNNN.png beside the HDF5 file); "
                        "with --all, a directory for frame_NNNNNN.png (default: frames/ beside it)")
    parser.add_argument("--size", type=float, default=7.0, help="figure size [inch]")
    parser.add_argument("--dpi", type=int, default=120)
    parser.add_argument("--json", metavar="FILE",
                        help="also write what was drawn: per picture, each circle (id, centre, "
                        "radius) and each superellipse outline (id, vertices)")
    args = parser.parse_args(argv)
    drawn = [] if args.json else None

    try:
        f = h5py.File(args.snapshots, "r")
    except OSError as e:
        print(f"render_snapshot.py: cannot open {args.snapshots}: {e}", file=sys.stderr)
        return 1
    with f:
        names = snapshot_names(f)
        if args.list:
            for i, name in enumerate(names):
                g = f["snapshots"][name]
                print(f"{i:6d}  {name}  t = {float(g.attrs['time']):.17g}  "
                      f"step {int(g.attrs['step'])}  {g['id'].shape[0]} particles")
            return 0
        if not names:
            print(f"render_snapshot.py: {args.snapshots} holds no snapshots", file=sys.stderr)
            return 1
        materials = material_names(f)
        drum = drum_geometry(args)
        base = os.path.dirname(os.path.abspath(args.snapshots))
        if args.all:
            outdir = args.output or os.path.join(base, "frames")
            os.makedirs(outdir, exist_ok=True)
            speed_max = 0.0
            if args.color == "speed":  # one colour scale for the whole sequence
                for name in names:
                    v = np.asarray(f["snapshots"][name]["velocity"][()]).reshape(-1, 2)
                    if len(v):
                        speed_max = max(speed_max, float(np.hypot(v[:, 0], v[:, 1]).max()))
            for name in names:
                out = os.path.join(outdir, f"frame_{name}.png")
                render(read_snapshot(f, name), materials, drum, args.color, speed_max, out,
                       args.size, args.dpi, drawn)
            print(f"{outdir}: {len(names)} frames")
            write_drawn(args.json, drawn)
            return 0
        if not -len(names) <= args.index < len(names):
            print(f"render_snapshot.py: no snapshot {args.index} ({len(names)} in the file)",
                  file=sys.stderr)
            return 1
        snap = read_snapshot(f, names[args.index])
        speed = np.hypot(snap["velocity"][:, 0], snap["velocity"][:, 1])
        out = args.output or os.path.join(base, f"snapshot_{snap['name']}.png")
        render(snap, materials, drum, args.color, float(speed.max()) if len(speed) else 0.0, out,
               args.size, args.dpi, drawn)
        write_drawn(args.json, drawn)
        print(f"{out}: snapshot {snap['name']}, t = {snap['time']:.6g} s, {len(speed)} particles")
    return 0


if __name__ == "__main__":
    sys.exit(main())
