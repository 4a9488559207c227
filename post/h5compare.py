#!/usr/bin/python3
"""Compare two dem2d snapshots.h5 files snapshot by snapshot, particles matched by id.

    post/h5compare.py A/snapshots.h5 B/snapshots.h5 [--atol 0] [--show 10] [--allow-added]
                      [--by-step]

Within each snapshot both files' particles are sorted by id, so runs on different rank counts
(whose files hold the particles in a different order) compare equal when the physics is the
same. Compared: the number and names of snapshots, their time and step attributes, the set of
ids, every per-particle dataset (id, material, position, velocity, angle, spin, radius: whatever
the files hold; a dataset in one file only is a difference), the particles' outline polygons
of scenes with superellipses (/outlines/NAME/points, as "outline", each particle's points
matched by id), the shell of runs with a [shell] (/shell/NAME's points, displacement and
von_mises, row by row: the mesh's nodes, the same in every run of a deck; /shell_mesh once) and
the /materials table. The datasets' unit and doc attributes and /xdmf (ParaView helper data)
are not compared.
With --by-step, snapshots are paired by their step attribute instead of their names: a run
that was interrupted (which wrote a last snapshot where it stopped) and restarted compares
with the uninterrupted run, the extra snapshot allowed by --allow-added.

Exit status: 0 when the files are bit-identical (or, with --atol, every floating-point value
is within atol and everything else is identical); 1 otherwise, after printing the first
differences and the largest absolute difference of each field; 2 for a usage or file error.
"""

import argparse
import sys

import h5py
import numpy as np

from snapshot_order import snapshot_key, snapshot_names


class Report:
    def __init__(self, show, allow_added=False):
        self.show = show
        self.allow_added = allow_added  # datasets only in the second file are not differences
        self.added = set()
        self.shown = 0
        self.differences = 0
        self.max_abs = {}  # field -> largest |a - b|

    def differ(self, text):
        self.differences += 1
        if self.shown < self.show:
            print(text)
            self.shown += 1

    def note_max(self, field, value):
        self.max_abs[field] = max(self.max_abs.get(field, 0.0), value)


def fmt(x):
    return repr(x.item()) if hasattr(x, "item") else repr(x)


def same_bits(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def compare_arrays(where, field, a, b, ids, atol, report):
    """Compare two arrays of equal length (rows matched); record the differences."""
    key = field if where.startswith("/snapshots") else f"{where.lstrip('/')}/{field}"
    if a.shape != b.shape:
        report.differ(f"{where}/{field}: shape {a.shape} vs {b.shape}")
        return
    if same_bits(a, b):
        report.note_max(key, 0.0)
        return
    floating = np.issubdtype(a.dtype, np.floating) and np.issubdtype(b.dtype, np.floating)
    if floating:
        a64, b64 = a.astype(np.float64), b.astype(np.float64)
        both_nan = np.isnan(a64) & np.isnan(b64)
        diff = np.where(both_nan, 0.0, np.abs(a64 - b64))
        diff = np.where(np.isnan(diff), np.inf, diff)  # nan vs number
        # Bitwise: -0.0 vs 0.0 or different NaN payloads differ too.
        bits_differ = a64.view(np.uint64) != b64.view(np.uint64)
        bad = (diff > atol) | (bits_differ & (atol == 0))
        report.note_max(key, float(diff.max()) if diff.size else 0.0)
    else:
        bad = a != b
        if np.issubdtype(a.dtype, np.number) and np.issubdtype(b.dtype, np.number):
            d = np.abs(a.astype(np.float64) - b.astype(np.float64))
            report.note_max(key, float(d.max()) if d.size else 0.0)
    if bad.ndim > 1:
        rows = np.nonzero(bad.any(axis=tuple(range(1, bad.ndim))))[0]
    else:
        rows = np.nonzero(bad)[0]
    for row in rows:
        label = f"id {ids[row]}" if ids is not None else f"row {row}"
        report.differ(f"{where}/{field}: {label}: {fmt(a[row]) if a.ndim == 1 else a[row].tolist()}"
                      f" vs {fmt(b[row]) if b.ndim == 1 else b[row].tolist()}")


def outline_rows(f, name, count):
    """The outline points of snapshot `name` as (N, K, 2) rows, or None when it has none."""
    if "outlines" not in f or name not in f["outlines"]:
        return None
    points = f["outlines"][name]["points"][()]
    return points.reshape(count, -1, 2) if count else points.reshape(0, 0, 2)


def compare_snapshot(name, ga, gb, atol, report, outlines=(None, None)):
    where = f"/snapshots/{name}"
    for attr in ("time", "step"):
        va, vb = ga.attrs.get(attr), gb.attrs.get(attr)
        if va is None or vb is None or not same_bits(np.asarray(va), np.asarray(vb)):
            if attr == "time" and va is not None and vb is not None and abs(va - vb) <= atol:
                continue
            report.differ(f"{where}@{attr}: {fmt(va)} vs {fmt(vb)}")
    ida, idb = ga["id"][()], gb["id"][()]
    for label, ids in (("first", ida), ("second", idb)):
        if len(np.unique(ids)) != len(ids):
            report.differ(f"{where}/id: duplicate ids in the {label} file")
    common, ia, ib = np.intersect1d(ida, idb, assume_unique=False, return_indices=True)
    only_a = np.setdiff1d(ida, idb)
    only_b = np.setdiff1d(idb, ida)
    if len(only_a) or len(only_b):
        report.differ(f"{where}/id: {len(only_a)} ids only in the first file "
                      f"{only_a[:5].tolist()}, {len(only_b)} only in the second {only_b[:5].tolist()}")
    fields = sorted(set(ga.keys()) | set(gb.keys()))
    for field in fields:
        if field not in ga and report.allow_added:
            report.added.add(field)
            continue
        if field not in ga or field not in gb:
            report.differ(f"{where}/{field}: only in the {'first' if field in ga else 'second'} file")
            continue
        a, b = ga[field][()], gb[field][()]
        if len(a) != len(ida) or len(b) != len(idb):
            report.differ(f"{where}/{field}: {len(a)} and {len(b)} rows for {len(ida)} and "
                          f"{len(idb)} particles")
            continue
        compare_arrays(where, field, a[ia], b[ib], common, atol, report)
    oa, ob = outlines
    if oa is None and ob is not None and report.allow_added:
        report.added.add("outline")
    elif (oa is None) != (ob is None):
        report.differ(f"/outlines/{name}: only in the {'first' if oa is not None else 'second'} file")
    elif oa is not None:
        compare_arrays(where, "outline", oa[ia], ob[ib], common, atol, report)


def compare_shell(fa, fb, name_a, name_b, atol, report):
    """The shell of a snapshot pair (/shell/NAME), row by row."""
    sa = fa["shell"][name_a] if "shell" in fa and name_a in fa["shell"] else None
    sb = fb["shell"][name_b] if "shell" in fb and name_b in fb["shell"] else None
    if sa is None and sb is not None and report.allow_added:
        report.added.add("shell")
    elif (sa is None) != (sb is None):
        report.differ(f"/shell/{name_a}: only in the {'first' if sa is not None else 'second'} file")
    elif sa is not None:
        for field in sorted(set(sa.keys()) | set(sb.keys())):
            if field not in sa or field not in sb:
                report.differ(f"/shell/{name_a}/{field}: only in one file")
                continue
            compare_arrays(f"/snapshots/{name_a}", f"shell/{field}", sa[field][()], sb[field][()],
                           None, atol, report)


def compare_shell_mesh(fa, fb, atol, report):
    """The shell's mesh (/shell_mesh), when either file has one."""
    ma, mb = fa.get("shell_mesh"), fb.get("shell_mesh")
    if ma is None and mb is not None and report.allow_added:
        report.added.add("shell_mesh")
    elif (ma is None) != (mb is None):
        report.differ("/shell_mesh: only in one file")
    elif ma is not None:
        for field in sorted(set(ma.keys()) | set(mb.keys())):
            if field not in ma or field not in mb:
                report.differ(f"/shell_mesh/{field}: only in one file")
                continue
            compare_arrays("/shell_mesh", field, ma[field][()], mb[field][()], None, atol, report)


def compare_materials(fa, fb, atol, report):
    ma, mb = fa.get("materials"), fb.get("materials")
    if ma is None or mb is None:
        if (ma is None) != (mb is None):
            report.differ("/materials: only in one file")
        return
    for field in sorted(set(ma.keys()) | set(mb.keys())):
        if field not in ma or field not in mb:
            report.differ(f"/materials/{field}: only in one file")
            continue
        a, b = ma[field][()], mb[field][()]
        if a.dtype.kind in "SOU" or b.dtype.kind in "SOU":
            if a.tolist() != b.tolist():
                report.differ(f"/materials/{field}: {a.tolist()} vs {b.tolist()}")
            continue
        compare_arrays("/materials", field, a, b, None, atol, report)


def paired_snapshots(fa, fb, by_step, report):
    """The (name in the first, name in the second) snapshot pairs to compare."""
    def keyed(f):
        names = snapshot_names(f)
        return {(int(f["snapshots"][n].attrs["step"]) if by_step else n): n for n in names}
    ka, kb = keyed(fa), keyed(fb)
    order = (lambda k: k) if by_step else snapshot_key  # steps are numbers; names by index
    only_a = sorted(set(ka) - set(kb), key=order)
    only_b = sorted(set(kb) - set(ka), key=order)
    what = "steps" if by_step else "names"
    if only_a or (only_b and not (by_step and report.allow_added)):
        report.differ(f"/snapshots: {len(ka)} snapshots vs {len(kb)}; "
                      f"{what} only in the first: {only_a[:5]}, only in the second: {only_b[:5]}")
    elif only_b:
        report.added.add(f"snapshots at steps {only_b[:5]}")
    return [(ka[k], kb[k]) for k in sorted(ka, key=order) if k in kb]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("first", help="a snapshots.h5")
    parser.add_argument("second", help="another snapshots.h5")
    parser.add_argument("--atol", type=float, default=0.0,
                        help="accept floating-point differences up to this (default 0: bit-identical)")
    parser.add_argument("--show", type=int, default=10, help="differences to print (default 10)")
    parser.add_argument("--allow-added", action="store_true",
                        help="per-particle datasets (and, with --by-step, snapshots) only in the second "
                             "file are listed, not counted as differences; every common one must match")
    parser.add_argument("--by-step", action="store_true",
                        help="pair snapshots by their step attribute, not by their names")
    args = parser.parse_args(argv)
    try:
        fa = h5py.File(args.first, "r")
        fb = h5py.File(args.second, "r")
    except OSError as e:
        print(f"h5compare.py: {e}", file=sys.stderr)
        return 2
    report = Report(args.show, args.allow_added)
    with fa, fb:
        compare_materials(fa, fb, args.atol, report)
        compare_shell_mesh(fa, fb, args.atol, report)
        common = paired_snapshots(fa, fb, args.by_step, report)
        for name_a, name_b in common:
            ga, gb = fa["snapshots"][name_a], fb["snapshots"][name_b]
            outlines = (outline_rows(fa, name_a, len(ga["id"])), outline_rows(fb, name_b, len(gb["id"])))
            compare_snapshot(name_a, ga, gb, args.atol, report, outlines)
            compare_shell(fa, fb, name_a, name_b, args.atol, report)
    if report.differences == 0:
        what = "bit-identical" if args.atol == 0 else f"identical within atol = {args.atol:g}"
        added = f"; datasets only in the second file: {', '.join(sorted(report.added))}" if report.added else ""
        print(f"{len(common)} snapshots {what}{added}")
        return 0
    if report.differences > report.shown:
        print(f"... {report.differences - report.shown} more differences")
    print(f"{report.differences} differences in {len(common)} common snapshots; "
          "max |difference| per field:")
    for field, value in sorted(report.max_abs.items()):
        print(f"  {field:28s} {value:.17g}")
    return 1


if __name__ == "__main__":
    sys.exit(main())
