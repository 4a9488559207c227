#!/usr/bin/python3
"""Compare two dem2d snapshot files particle by particle, sorted by id.

Usage: compare_snapshots.py A/snapshots.h5 B/snapshots.h5 [--tolerance 0]

Every snapshot group present in both files is compared: the same times and steps, the same
set of ids, and every dataset (position, velocity, spin, radius, material and any extra field)
equal after sorting both by id, bit for bit by default (--tolerance gives a relative one).
Prints one line per snapshot; exit status 0 when all agree, 1 otherwise, 2 on bad input.
"""
import argparse
import sys

import h5py
import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--tolerance", type=float, default=0.0,
                    help="relative tolerance (default 0: bit for bit)")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args()
    try:
        fa, fb = h5py.File(args.a, "r"), h5py.File(args.b, "r")
    except OSError as e:
        print(f"compare_snapshots: error: {e}", file=sys.stderr)
        return 2
    ga, gb = fa["snapshots"], fb["snapshots"]
    names = sorted(set(ga) & set(gb))
    if not names or set(ga) != set(gb):
        print(f"compare_snapshots: snapshot groups differ: {len(ga)} in {args.a}, {len(gb)} in {args.b}")
        return 1
    bad = 0
    for name in names:
        sa, sb = ga[name], gb[name]
        ok = True
        why = []
        for attr in ("time", "step"):
            if sa.attrs[attr] != sb.attrs[attr]:
                ok = False
                why.append(f"{attr} {sa.attrs[attr]} != {sb.attrs[attr]}")
        ia, ib = sa["id"][...], sb["id"][...]
        oa, ob = np.argsort(ia, kind="stable"), np.argsort(ib, kind="stable")
        if not np.array_equal(ia[oa], ib[ob]):
            ok = False
            why.append(f"id sets differ ({ia.size} vs {ib.size} particles)")
        else:
            for key in sorted(set(sa) | set(sb)):
                if key not in sa or key not in sb:
                    ok = False
                    why.append(f"dataset {key} missing in one file")
                    continue
                xa, xb = sa[key][...][oa], sb[key][...][ob]
                if args.tolerance == 0.0:
                    same = np.array_equal(xa.view(np.uint8), xb.view(np.uint8)) if xa.dtype == xb.dtype else False
                else:
                    scale = np.maximum(np.abs(xa), np.abs(xb))
                    same = bool(np.all(np.abs(xa - xb) <= args.tolerance * np.maximum(scale, 1e-300)))
                if not same:
                    ok = False
                    diff = np.max(np.abs(xa.astype(float) - xb.astype(float)))
                    why.append(f"{key} differs (max |diff| {diff:.3g})")
        if not ok:
            bad += 1
        if not args.quiet or not ok:
            print(f"{name} t = {sa.attrs['time']:.6g}: {'identical' if ok else 'DIFFERENT: ' + '; '.join(why)}")
    print(f"{len(names) - bad} of {len(names)} snapshots agree")
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
