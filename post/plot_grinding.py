#!/usr/bin/python3
"""Plot what an ore scene ground: the product's size distribution and the ore in the mill.

    post/plot_grinding.py OUTDIR [-o grinding.png]

Reads OUTDIR/product.csv (every particle the sieve let out), OUTDIR/breakages.csv and
OUTDIR/series.csv, and OUTDIR/snapshots.h5 for the ore in the mill. Four panels:
  - the product's cumulative mass distribution by radius (% passing), and its count;
  - the ore in the mill at several times: cumulative mass distribution by radius;
  - counts against time: breakages, fragments, fed, discharged;
  - masses against time: ore in the mill, fed, discharged, and the mass-balance error
    (initial mill mass + fed - mill mass - discharged), which must stay at round-off.
Prints a one-line summary (breakages, discharged mass, grinding rate in kg/s).
"""

import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import h5py  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from snapshot_order import snapshot_names  # noqa: E402


def read_csv(path):
    """A CSV as a dict of column -> float array (empty arrays for a header-only file)."""
    with open(path, encoding="ascii") as f:
        rows = list(csv.DictReader(f))
        names = rows[0].keys() if rows else []
    return {n: np.array([float(r[n]) for r in rows]) for n in names}


def cumulative(radius, mass):
    """Radii sorted and the cumulative mass fraction passing (%)."""
    order = np.argsort(radius)
    m = np.cumsum(mass[order])
    return radius[order], 100.0 * m / m[-1]


def ore_in_mill(h5_path, ore_index, count=4):
    """(time, radii, masses) of the ore in `count` snapshots spread over the run."""
    out = []
    with h5py.File(h5_path, "r") as f:
        keys = snapshot_names(f)
        for key in [keys[i] for i in np.linspace(0, len(keys) - 1, min(count, len(keys))).astype(int)]:
            g = f["snapshots"][key]
            ore = g["material"][:] == ore_index
            r = g["radius"][:][ore]
            out.append((float(g.attrs["time"]), r, r ** 3))  # mass ~ r^3 within one material
    return out


def ore_material(h5_path):
    """Index of the material that carries damage (the ore), else 0."""
    with h5py.File(h5_path, "r") as f:
        keys = snapshot_names(f)
        g = f["snapshots"][keys[-1]]
        if "damage" not in g:
            return 0
        mats, dmg = g["material"][:], g["damage"][:]
        hit = mats[dmg > 0]
        return int(np.bincount(hit).argmax()) if len(hit) else int(np.bincount(mats).argmin())


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("outdir")
    ap.add_argument("-o", "--output", default=None)
    a = ap.parse_args()
    d = a.outdir
    series = read_csv(os.path.join(d, "series.csv"))
    product = read_csv(os.path.join(d, "product.csv"))
    t = series["time"]
    fig, ax = plt.subplots(2, 2, figsize=(12, 8))

    p = ax[0, 0]
    if len(product.get("radius", [])):
        r, c = cumulative(product["radius"], product["mass"])
        p.plot(1000 * r, c, drawstyle="steps-post")
        p.set_title(f"product: {len(r)} particles, {product['mass'].sum():.3g} kg")
    else:
        p.set_title("product: none yet")
    p.set_xlabel("radius [mm]")
    p.set_ylabel("cumulative mass passing [%]")

    p = ax[0, 1]
    h5 = os.path.join(d, "snapshots.h5")
    if os.path.exists(h5):
        for time, r, m in ore_in_mill(h5, ore_material(h5)):
            if len(r):
                rr, c = cumulative(r, m)
                p.plot(1000 * rr, c, drawstyle="steps-post", label=f"t = {time:.2f} s ({len(r)})")
        p.legend(fontsize=8)
    p.set_title("ore in the mill")
    p.set_xlabel("radius [mm]")
    p.set_ylabel("cumulative mass [%]")

    p = ax[1, 0]
    for col, label in [("breakages", "breakages"), ("fragments", "fragments born"),
                       ("fed_count", "fed"), ("discharged_count", "discharged")]:
        p.plot(t, series[col], label=label)
    p.set_xlabel("time [s]")
    p.set_ylabel("count since the start")
    p.legend(fontsize=8)

    p = ax[1, 1]
    m0 = series["mill_mass"][0]
    p.plot(t, series["ore_mass"], label="ore in the mill")
    p.plot(t, series["fed_mass"], label="fed")
    p.plot(t, series["discharged_mass"], label="discharged")
    err = m0 + series["fed_mass"] - series["mill_mass"] - series["discharged_mass"]
    p.set_title(f"mass balance error: max {np.max(np.abs(err)) / m0:.2g} of the mill mass")
    p.set_xlabel("time [s]")
    p.set_ylabel("mass [kg]")
    p.legend(fontsize=8)

    fig.tight_layout()
    out = a.output or os.path.join(d, "grinding.png")
    fig.savefig(out, dpi=110)
    rate = series["discharged_mass"][-1] / t[-1] if t[-1] > 0 else 0.0
    print(f"{int(series['breakages'][-1])} breakages, {series['discharged_mass'][-1]:.4g} kg "
          f"discharged in {t[-1]:.4g} s ({rate:.4g} kg/s); wrote {out}")


if __name__ == "__main__":
    main()
