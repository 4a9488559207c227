#!/usr/bin/python3
"""Population-balance parameters measured from a dem2d grinding run, and the population-balance
model (PBM) run forward against the DEM.

    post/pbm.py OUTDIR [--classes RATIO] [--top D] [--window T0 T1] [--dt DT]
                       [-o pbm.csv] [--plot pbm.png]

The PBM: ore mass m_i(t) in size classes i (i = 0 the coarsest),
    dm_i/dt = f_i - S_i m_i + sum_{j < i} b_ij S_j m_j - d_i m_i.

Classes. Diameter edges D, D/r, D/r^2, ... down to breakage.fines_diameter (r = --classes,
default sqrt(2); the last coarse class is cut at the fines diameter, so it may be narrower), then
one class [0, fines_diameter) for everything finer. D (--top) defaults to the largest ore
diameter the deck can make (2 x the largest radius_max / radius of the ore's [[fill]],
[[particle]] and [feed]) or seen in the run, whichever is larger; the top class includes D.
A class is [d_lo, d_hi): a particle is in it when d_lo <= 2 radius < d_hi.

Window. T0 and T1 (default: breakage.start and the end of the run) are moved to the nearest
snapshot times; an event (break, discharge, feed) at time t is in the window when T0 < t <= T1
(a snapshot at time t already shows the events of its step).

Measured over the window (T = T1 - T0; mbar_i = the mass held in class i, time-averaged over
the snapshots in the window with the trapezoidal rule):
  - B_j: the mass of the class-j parents broken (breakages.csv); P_ij: their progeny in class i,
    fragments.csv plus the break's fines_mass, all of it lumped in the finest class (every fine
    is below fines_diameter, the finest class's upper edge, so lumping is exact here: the t10
    spread below fines_diameter would only subdivide that one class).
  - S_j = (B_j - P_jj) / (mbar_j T): the mass broken OUT of class j per second per kg held, net
    of the progeny that stays in class j (the PBM above has no b_jj term).
  - b_ij = P_ij / (B_j - P_jj) for i > j: each column sums to 1 where class j broke.
  - d_i = (discharged mass of class i: product.csv) / (mbar_i T). The fines leave the mill at
    once: the finest class has d = inf and holds nothing.
  - f_i = (mass fed in class i during the window) / T, from the fed particles themselves: the
    ids that are neither in the first snapshot nor fragments, sized where they are seen (a
    snapshot, breakages.csv, product.csv); fed in the window when absent from the snapshot at T0
    and not removed by T0, and present at T1 or removed by T1. Checked against series.csv's
    fed_mass and, per quarter-octave class over the whole run, against sizes.csv's fed_mass.
  - A class that held nothing at the snapshots but had mass pass through it (born and gone
    between two snapshots) gets S and/or d = inf: its inflow is passed on at once, broken and
    discharged in the ratio of broken_net_kg to discharged_kg.
  - Collisions (collisions.csv, output.collision_spectra = true): the spectra hold every contact
    that ended since t = 0, so this part is measured over the whole run [0, t_end], with the
    hold-up time-averaged over the same span (held_run_kg). Only contact types with "ore" in
    their name count; a contact's energy (its peak normal strain energy) goes to the class of
    its smaller body. A spectra class [a, b) is shared among the PBM classes it overlaps in
    proportion to the time-averaged number of ore particles held in each overlap (in log-size
    overlap where no particle was held). When the edges coincide the shares are 0 or 1 and the
    mapping is exact: give the run output.size_class_min = D / r^k and
    output.size_class_ratio = r (collisions.csv prints its edges to 6 digits: an edge within
    1e-5 relative of a PBM edge is taken as that edge). Energies in spectra classes above D are
    left out (reported); a spectra class that reaches above the bottom edge (fines_diameter)
    is cut there, as no ore is held below it.
    specific_collision_power_W_kg = collision energy of the class / (held_run_kg x t_end);
    mean_collision_energy_J = that energy / collisions.

Files (-o pbm.csv; the others beside it, named after it):
  pbm.csv          one row per class, coarsest first: i, d_lo, d_hi (m), held_kg (mbar_i),
                   S_per_s, d_per_s, feed_kg_s, specific_collision_power_W_kg, collisions
                   (contacts ended over [0, t_end], shared as above, so not always whole),
                   then mean_collision_energy_J, held_run_kg, broken_kg (B_i, gross),
                   broken_net_kg (B_i - P_ii), discharged_kg, fed_kg, held_start_kg,
                   held_end_kg (the snapshots at T0 and T1), t0, t1.
  pbm_breakage.csv the breakage function in long form, one row per pair i > j (zeros included):
                   i, j, b_ij, d_lo_i, d_hi_i, d_lo_j, d_hi_j.
  pbm_forward.csv  the forward run against the DEM, one row per class: i, d_lo, d_hi,
                   product_dem_kg, product_pbm_kg (discharged over the window, fines included),
                   product_dem_passing, product_pbm_passing (cumulative % of the product below
                   d_hi), mill_dem_kg, mill_pbm_kg (held at T1), mill_dem_passing,
                   mill_pbm_passing.

Forward model: from the DEM's mill contents at T0 (the snapshot), over the window, with the
measured f, S, b, d, by implicit (backward) Euler with step --dt (default 1e-3 s; the system is
lower triangular, so each step solves the classes coarsest first; unconditionally stable and
mass-conserving). Prints a table per class and one summary line: the total product of both and
the largest absolute difference in cumulative % passing of the product and of the mill.

Tolerance: with parameters measured from the same run the PBM must reproduce the DEM's product
to within 5 % passing in every class (PRODUCT_TOLERANCE) and 10 % in mass (TOTAL_TOLERANCE).
What the DEM broke and discharged over the window equals S_i mbar_i T and d_i mbar_i T exactly,
so the PBM would reproduce it exactly if its hold-up m_i(t) followed the DEM's; the error is the
mean-field one, that constant S, d and f spread over the window what the DEM does in bursts
(its rates still rise while the charge develops and the mill fills), plus the trapezoidal
average over the snapshots. It shows mostly in the product's mass: the progeny of a break
leaves some 1/d later (0.3-2 s here), so a window of length T whose breaks are bunched early
or late moves some (1/d)/T of the product across T1; the size distribution (% passing) hardly
moves. Measured on the grate mill (inputs/grinding_grate.in, f_mat = 0.5, runs of 3-6 s):
windows of 2 s or more that start once breakage is under way stayed within 1.8 % passing and
6 % in mass (0.5-6 s: 0.4 % and +5.6 %); a 1.5 s window +8 %, a 1 s window +17 %; a window from
breakage.start = 0.5 s on a 3 s run, whose first half broke a tenth of its second, +31 % in mass
(0.97 % passing: exit 2). The line
"broken in the window's halves" shows how evenly the DEM broke. Exit 2 when the product misses
the tolerance (the files are written all the same).

Exact bookkeeping, checked first (exit 1 with a message naming what broke):
  - every break: the parent's mass (= 4/3 pi r^3 rho) = its fragments' masses (fragments.csv,
    ids first_fragment_id .. + fragments - 1) + fines_mass, to 1e-9 relative;
  - every column of b sums to 1 to 1e-9 where the class broke;
  - the window's mass balance, held at T0 + fed - discharged (fines included) = held at T1, to
    1e-6 relative, from the particles; against series.csv (fed_mass, discharged_mass, ore_mass)
    where it has rows at T0 and T1; and per class (held change = fed + progeny - broken -
    discharged); over the whole run against sizes.csv (initial, fed, product and mill masses).

Uses numpy, h5py and matplotlib (only for --plot).
"""

import argparse
import csv
import json
import math
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from snapshot_order import snapshot_names  # noqa: E402

PRODUCT_TOLERANCE = 5.0  # % passing: the forward model's product against the DEM's
TOTAL_TOLERANCE = 10.0  # %: the forward model's total product against the DEM's
BREAK_TOLERANCE = 1e-9  # relative: a break's mass, b's column sums
BALANCE_TOLERANCE = 1e-6  # relative: mass balances between files


class Bookkeeping(Exception):
    """The run's files contradict each other (exit 1)."""


def read_rows(path, numeric):
    """A CSV as a dict of column -> float array, converting only the `numeric` columns."""
    with open(path, encoding="ascii") as f:
        reader = csv.DictReader(f)
        missing = [c for c in numeric if c not in (reader.fieldnames or [])]
        if missing:
            raise Bookkeeping(f"{path}: no column {', '.join(missing)}")
        cols = {c: [] for c in numeric}
        for row in reader:
            for c in numeric:
                cols[c].append(float(row[c]))
    return {c: np.array(v, dtype=float) for c, v in cols.items()}


def sphere_mass(r, density):
    # As dem2d's Disc::mass: 4/3 pi r^3 rho, in the same order of operations.
    return 4.0 / 3.0 * math.pi * r * r * r * density


def relative_gap(a, b, scale=None):
    scale = max(abs(a), abs(b)) if scale is None else scale
    return abs(a - b) / scale if scale > 0 else abs(a - b)


# --------------------------------------------------------------------------------------------
# Classes


def pbm_edges(top, ratio, fines):
    """Edges from the top down: [top, top/r, ..., > fines, fines, 0]."""
    edges = [top]
    while True:
        nxt = edges[-1] / ratio
        if nxt <= fines * (1.0 + 1e-9):
            break
        edges.append(nxt)
    edges += [fines, 0.0]
    return np.array(edges)


def classify(edges, diameters):
    """The PBM class (0 = coarsest) of each diameter; the top edge belongs to the top class."""
    asc = edges[::-1]  # 0, fines, ..., top
    n = len(edges) - 1
    j = np.searchsorted(asc, np.asarray(diameters, dtype=float), side="right") - 1
    j = np.clip(j, 0, n - 1)
    return n - 1 - j


def binned(edges, diameters, masses):
    n = len(edges) - 1
    out = np.zeros(n)
    if len(diameters):
        np.add.at(out, classify(edges, diameters), masses)
    return out


def quarter_octave_class(d):
    """sizes.csv's class of each diameter: edge(k-1) <= d < edge(k), edge(k) = 1e-6 2^(k/4)."""
    d = np.asarray(d, dtype=float)
    k = np.clip(np.floor(4.0 * np.log2(np.maximum(d, 1e-300) / 1e-6)).astype(int) + 1, 0, 95)
    k = np.where(d < 1e-6, 0, k)
    edge = lambda kk: 1e-6 * np.exp2(0.25 * kk)  # noqa: E731
    k = np.where((k > 1) & (d < edge(k - 1)), k - 1, k)
    k = np.where((k < 95) & (d >= edge(k)), k + 1, k)
    return k


# --------------------------------------------------------------------------------------------
# Reading the run


class Run:
    def __init__(self, outdir):
        self.dir = outdir
        path = lambda name: os.path.join(outdir, name)  # noqa: E731
        for name in ("run.json", "breakages.csv", "fragments.csv", "product.csv", "series.csv",
                     "sizes.csv", "snapshots.h5"):
            if not os.path.exists(path(name)):
                raise Bookkeeping(f"{path(name)}: missing (pbm.py needs an ore run's output)")
        with open(path("run.json"), encoding="utf-8") as f:
            self.info = json.load(f)
        deck = self.info["deck"]
        self.deck = deck
        br = deck.get("breakage") or {}
        if not br.get("material"):
            raise Bookkeeping(f"{path('run.json')}: the deck has no [breakage] material")
        self.ore_name = br["material"]
        # t10 progeny: fines below fines_diameter. Other fragment laws make no fines: the
        # bottom edge is then the smallest ore diameter of the run (set after reading).
        self.fines = float(br.get("fines_diameter", 0.0) or 0.0)
        self.start = float(br.get("start", 0.0))
        self.breaks = read_rows(path("breakages.csv"),
                                ["time", "parent_id", "radius", "fragments", "first_fragment_id",
                                 "mass", "t10", "fines_mass"])
        self.frags = read_rows(path("fragments.csv"), ["time", "parent_id", "id", "radius", "mass"])
        self.product = read_rows(path("product.csv"), ["time", "id", "radius", "mass"])
        self.series = read_rows(path("series.csv"),
                                ["time", "fed_mass", "discharged_mass", "ore_mass"])
        with open(path("sizes.csv"), encoding="ascii") as f:
            rows = list(csv.DictReader(f))
        self.sizes = {c: np.array([float(r[c]) for r in rows])
                      for c in ("diameter", "initial_mass", "fed_mass", "product_mass",
                                "mill_mass")}
        self.collisions = None
        if os.path.exists(path("collisions.csv")):
            with open(path("collisions.csv"), encoding="ascii") as f:
                self.collisions = list(csv.DictReader(f))
        self._read_snapshots(path("snapshots.h5"))
        self.has_fines = self.fines > 0.0
        if not self.has_fines:
            smallest = [2.0 * r.min() for r in self.radii if len(r)]
            for arr in (self.frags["radius"], self.product["radius"], self.breaks["radius"]):
                if len(arr):
                    smallest.append(2.0 * arr.min())
            if not smallest:
                raise Bookkeeping(f"{outdir}: no ore particle anywhere in the run")
            self.fines = min(smallest)
            if np.any(self.breaks["fines_mass"] != 0.0):
                raise Bookkeeping(f"{path('breakages.csv')}: fines without a fines_diameter")

    def _read_snapshots(self, h5path):
        with h5py.File(h5path, "r") as f:
            names = [n.decode() if isinstance(n, bytes) else str(n)
                     for n in f["materials/name"][()]]
            if self.ore_name not in names:
                raise Bookkeeping(f"{h5path}: no material '{self.ore_name}' in /materials")
            self.ore = names.index(self.ore_name)
            self.density = float(f["materials/density"][()][self.ore])
            self.times, self.ids, self.radii, self.all_ids = [], [], [], []
            for name in snapshot_names(f):
                s = f["snapshots"][name]
                mat = s["material"][()]
                ids = s["id"][()]
                r = s["radius"][()]
                ore = mat == self.ore
                self.times.append(float(s.attrs["time"]))
                self.ids.append(ids[ore])
                self.radii.append(r[ore])
                self.all_ids.append(ids)
        if len(self.times) < 2:
            raise Bookkeeping(f"{h5path}: {len(self.times)} snapshot(s); pbm.py needs two or more")
        self.times = np.array(self.times)
        self.masses = [sphere_mass(r, self.density) for r in self.radii]

    def largest_ore_diameter(self):
        """The largest ore diameter the deck can make (fills, particles, feed), else 0."""
        d = 0.0
        for key in ("fill", "particle"):
            for item in self.deck.get(key) or []:
                if item.get("material") == self.ore_name:
                    for k in ("radius_max", "radius"):
                        if k in item:
                            d = max(d, 2.0 * float(item[k]))
        feed = self.deck.get("feed") or {}
        if feed.get("material") == self.ore_name and "radius_max" in feed:
            d = max(d, 2.0 * float(feed["radius_max"]))
        return d

    def largest_seen_diameter(self):
        seen = [2.0 * r.max() for r in self.radii if len(r)]
        for arr in (self.breaks["radius"], self.product["radius"]):
            if len(arr):
                seen.append(2.0 * arr.max())
        return max(seen) if seen else 0.0


# --------------------------------------------------------------------------------------------
# The exact bookkeeping


def check_breaks(run):
    """Every break's parent mass = its fragments + fines_mass (1e-9 relative); fragments.csv's
    rows all belong to a break. Returns {parent_id: (fragment radii, fragment masses)}."""
    b, fr = run.breaks, run.frags
    by_parent = {}
    for k in range(len(fr["id"])):
        by_parent.setdefault(int(fr["parent_id"][k]), []).append(k)
    seen = set()
    out = {}
    for k in range(len(b["time"])):
        pid, t = int(b["parent_id"][k]), b["time"][k]
        what = f"the break of particle {pid} at t = {t:.9g} s (breakages.csv row {k + 2})"
        if pid in seen:
            raise Bookkeeping(f"{what}: particle {pid} broke twice")
        seen.add(pid)
        n, first = int(b["fragments"][k]), int(b["first_fragment_id"][k])
        rows = by_parent.get(pid, [])
        ids = sorted(int(fr["id"][j]) for j in rows)
        if ids != list(range(first, first + n)):
            raise Bookkeeping(f"{what}: fragments.csv lists {len(ids)} fragment(s) of it, ids "
                              f"{ids[:8]}{' ...' if len(ids) > 8 else ''}; breakages.csv says {n}, "
                              f"ids {first} to {first + n - 1}")
        if any(fr["time"][j] != t for j in rows):
            raise Bookkeeping(f"{what}: fragments.csv gives its fragments another time")
        parent = b["mass"][k]
        from_radius = sphere_mass(b["radius"][k], run.density)
        if relative_gap(parent, from_radius) > BREAK_TOLERANCE:
            raise Bookkeeping(f"{what}: mass {parent!r} kg, but its radius gives "
                              f"{from_radius!r} kg")
        frag_mass = float(np.sum(fr["mass"][rows])) if rows else 0.0
        total = frag_mass + b["fines_mass"][k]
        if relative_gap(parent, total) > BREAK_TOLERANCE:
            raise Bookkeeping(f"{what}: parent mass {parent!r} kg != fragments {frag_mass!r} kg "
                              f"+ fines {b['fines_mass'][k]!r} kg (relative gap "
                              f"{relative_gap(parent, total):.3g} > {BREAK_TOLERANCE:g})")
        out[pid] = (fr["radius"][rows], fr["mass"][rows])
    orphans = sorted(set(by_parent) - seen)
    if orphans:
        raise Bookkeeping(f"fragments.csv: fragments of particle(s) {orphans[:8]} that "
                          "breakages.csv never broke")
    return out


def fed_particles(run):
    """The fed ore particles: {id: (radius, removal time or inf)}, from the id gaps."""
    initial = set(run.all_ids[0].tolist())
    frag_ids = set(run.frags["id"].astype(np.int64).tolist())
    radius, removed = {}, {}
    for arr_id, arr_r, arr_t in (
            (run.breaks["parent_id"], run.breaks["radius"], run.breaks["time"]),
            (run.product["id"], run.product["radius"], run.product["time"])):
        for i, r, t in zip(arr_id.astype(np.int64).tolist(), arr_r.tolist(), arr_t.tolist()):
            if i in removed:
                raise Bookkeeping(f"particle {i} leaves the mill twice (breakages.csv and "
                                  f"product.csv at t = {removed[i]:.9g} s and {t:.9g} s)")
            radius[i], removed[i] = r, t
    other = set()
    for ids, all_ids, r in zip(run.ids, run.all_ids, run.radii):
        for i, ri in zip(ids.tolist(), r.tolist()):
            radius.setdefault(i, ri)
        other.update(set(all_ids.tolist()) - set(ids.tolist()))
    every = set(radius) | initial | frag_ids | other
    top = max(every) if every else -1
    fed = {}
    unseen = []
    for i in range(top + 1):
        if i in initial or i in frag_ids or i in other:
            continue
        if i not in radius:
            unseen.append(i)
            continue
        fed[i] = (radius[i], removed.get(i, math.inf))
    if unseen:
        raise Bookkeeping(f"particle id(s) {unseen[:8]}: neither in the first snapshot nor a "
                          "fragment, and never seen (no snapshot, breakages.csv or product.csv "
                          "row): a row is missing")
    return fed, removed


# --------------------------------------------------------------------------------------------
# Measuring


def time_average(times, values):
    """Trapezoidal time average of values (snapshots x classes) over times."""
    times = np.asarray(times)
    if len(times) < 2 or times[-1] <= times[0]:
        return values[0].copy()
    dt = np.diff(times)[:, None]
    return (0.5 * dt * (values[1:] + values[:-1])).sum(axis=0) / (times[-1] - times[0])


def nearest_snapshot(times, t):
    return int(np.argmin(np.abs(times - t)))


def spectra_classes(run, edges, snap_counts_fn):
    """Collision energy and counts of the ore contact types by PBM class (over [0, t_end])."""
    n = len(edges) - 1
    energy, count = np.zeros(n), np.zeros(n)
    if run.collisions is None:
        return None
    cells = {}
    for row in run.collisions:
        if "ore" not in row["type"].split("-"):
            continue
        key = (row["type"], float(row["size_min"]), float(row["size_max"]))
        e, c = cells.get(key, (float(row["energy"]), 0))
        cells[key] = (e, c + int(row["count"]))
    # collisions.csv prints the edges to 6 digits: one within 1e-5 of a PBM edge is that edge.
    def snap(x):
        for e in edges[:-1]:
            if abs(x - e) <= 1e-5 * e:
                return float(e)
        return x

    bins = {}
    for (_, lo, hi), (e, c) in cells.items():
        lo, hi = snap(lo), snap(hi)
        be, bc = bins.get((lo, hi), (0.0, 0))
        bins[(lo, hi)] = (be + e, bc + c)
    left_out = 0.0
    top = edges[0]
    bottom = edges[-2]  # no ore is held below it (fines leave at once)
    for (a, b), (e, c) in sorted(bins.items()):
        if b > bottom:
            a = max(a, bottom)
        shares = np.zeros(n)
        held_in = snap_counts_fn(a, b)
        for i in range(n):
            lo, hi = edges[i + 1], edges[i]
            if i == 0:
                hi = top * (1.0 + 1e-12)  # the top class includes its upper edge
            x, y = max(a, lo), min(b, hi)
            if y <= x:
                continue
            if held_in > 0:
                shares[i] = snap_counts_fn(x, y) / held_in
            elif math.isfinite(b) and a > 0:
                shares[i] = math.log(y / x) / math.log(b / a)
            elif math.isfinite(b):
                shares[i] = (y - x) / (b - a)
        # What lies above the top is left out (shares add up to 1 to round-off otherwise).
        if shares.sum() < 1.0 - 1e-9:
            left_out += e * (1.0 - shares.sum())
        energy += e * shares
        count += c * shares
    return energy, count, left_out, sorted(bins)


def forward(m0, f, S, d, b, T, dt, instant, split):
    """Implicit Euler over [0, T]: returns (m(T), cumulative product per class, times, totals).

    instant[i]: the class passes its inflow on at once, a fraction split[i] broken, the rest
    discharged. The finest class is instant with split 0 (the fines leave at once)."""
    n = len(m0)
    steps = max(1, int(math.ceil(T / dt - 1e-9)))
    h = T / steps
    m = m0.astype(float).copy()
    prod = np.zeros(n)
    hist_t, hist_m = [0.0], [m.sum()]
    for _ in range(steps):
        inflow = f.copy()
        new = np.zeros(n)
        for i in range(n):
            if instant[i]:
                out = inflow[i] + m[i] / h  # anything held leaves in this step
                broken = split[i] * out
                prod[i] += (out - broken) * h
                new[i] = 0.0
            else:
                new[i] = (m[i] + h * inflow[i]) / (1.0 + h * (S[i] + d[i]))
                broken = S[i] * new[i]
                prod[i] += d[i] * new[i] * h
            if broken:
                inflow[i + 1:] += b[i + 1:, i] * broken
        m = new
        hist_t.append(hist_t[-1] + h)
        hist_m.append(m.sum())
    return m, prod, np.array(hist_t), np.array(hist_m), h


def passing(masses):
    """Cumulative % of the mass in each class and the finer ones (classes coarsest first)."""
    total = masses.sum()
    cum = np.cumsum(masses[::-1])[::-1]
    return 100.0 * cum / total if total > 0 else np.full(len(masses), np.nan)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("outdir", help="a dem2d ore run's output directory")
    ap.add_argument("--classes", type=float, default=math.sqrt(2.0), metavar="RATIO",
                    help="ratio between PBM class edges (default sqrt(2))")
    ap.add_argument("--top", type=float, default=None, metavar="D",
                    help="the top class edge (m; default the largest ore diameter)")
    ap.add_argument("--window", type=float, nargs=2, metavar=("T0", "T1"), default=None,
                    help="measurement window (s; default breakage.start to the end)")
    ap.add_argument("--dt", type=float, default=1e-3, help="PBM time step (s; default 1e-3)")
    ap.add_argument("-o", "--output", default=None, help="pbm.csv (default OUTDIR/pbm.csv)")
    ap.add_argument("--plot", default=None, metavar="PNG", help="draw the comparison")
    a = ap.parse_args()
    if not a.classes > 1.0:
        ap.error("--classes must be above 1")
    try:
        return run_pbm(a)
    except Bookkeeping as e:
        print(f"pbm.py: error: {e}", file=sys.stderr)
        return 1


def run_pbm(a):
    run = Run(a.outdir)
    frag_of = check_breaks(run)
    fed, removed = fed_particles(run)

    top = a.top if a.top else max(run.largest_ore_diameter(), run.largest_seen_diameter())
    if top < run.largest_seen_diameter() * (1.0 - 1e-12):
        raise Bookkeeping(f"--top {top}: below the largest ore diameter of the run "
                          f"({run.largest_seen_diameter():.6g} m)")
    if not top > run.fines:
        raise Bookkeeping(f"the top edge {top} m is not above the bottom edge {run.fines} m")
    edges = pbm_edges(top, a.classes, run.fines)
    n = len(edges) - 1
    F = n - 1  # the fines class

    times = run.times
    t_end = times[-1]
    w0, w1 = a.window if a.window else (run.start, t_end)
    s0, s1 = nearest_snapshot(times, w0), nearest_snapshot(times, w1)
    if s1 <= s0:
        raise Bookkeeping(f"the window {w0:g}-{w1:g} s holds fewer than two snapshots "
                          f"(snapshots at {times[0]:g} .. {times[-1]:g} s)")
    T0, T1 = times[s0], times[s1]
    T = T1 - T0
    notes = []
    if abs(T0 - w0) > 1e-6 or abs(T1 - w1) > 1e-6:
        notes.append(f"window moved to the snapshots: {T0:.6g}-{T1:.6g} s")

    # Hold-up by class at every snapshot.
    held = np.array([binned(edges, 2.0 * r, m) for r, m in zip(run.radii, run.masses)])
    mbar = time_average(times[s0:s1 + 1], held[s0:s1 + 1])
    mbar_run = time_average(times, held)
    held0, held1 = held[s0], held[s1]

    # Breaks in the window: gross broken mass B_j and progeny P_ij.
    br = run.breaks
    inwin = lambda t: (t > T0) & (t <= T1)  # noqa: E731
    B = np.zeros(n)
    P = np.zeros((n, n))
    fines_window = 0.0
    bw = inwin(br["time"])
    for k in np.nonzero(bw)[0]:
        pid = int(br["parent_id"][k])
        j = int(classify(edges, [2.0 * br["radius"][k]])[0])
        B[j] += br["mass"][k]
        fr_r, fr_m = frag_of[pid]
        if len(fr_r):
            np.add.at(P[:, j], classify(edges, 2.0 * fr_r), fr_m)
        P[F, j] += br["fines_mass"][k]
        fines_window += br["fines_mass"][k]
    if np.any(np.triu(P, 1) > 0):
        raise Bookkeeping("a fragment lands in a coarser class than its parent")
    net = B - np.diag(P)
    bmat = np.zeros((n, n))
    for j in range(n):
        if net[j] > 0:
            bmat[j + 1:, j] = P[j + 1:, j] / net[j]
            s = bmat[:, j].sum()
            if abs(s - 1.0) > BREAK_TOLERANCE:
                raise Bookkeeping(f"column {j} of b sums to {s!r}, not 1")

    # Discharge in the window (the particles; the fines go to the finest class).
    pr = run.product
    pw = inwin(pr["time"])
    D = binned(edges, 2.0 * pr["radius"][pw], pr["mass"][pw])
    product_dem = D.copy()
    product_dem[F] += fines_window

    # Feed in the window.
    present0 = set(run.ids[s0].tolist())
    present1 = set(run.ids[s1].tolist())
    fed_r = []
    for i, (r, t_out) in fed.items():
        if i in present0 or t_out <= T0:
            continue
        if i in present1 or t_out <= T1:
            fed_r.append(r)
    fed_r = np.array(fed_r)
    Fd = binned(edges, 2.0 * fed_r, sphere_mass(fed_r, run.density))

    # ---- mass balances ----
    scale = held1.sum() + Fd.sum() + product_dem.sum()
    gap = held0.sum() + Fd.sum() - product_dem.sum() - held1.sum()
    if abs(gap) > BALANCE_TOLERANCE * scale:
        raise Bookkeeping(f"window mass balance: held {held0.sum():.9g} kg at {T0:.6g} s + fed "
                          f"{Fd.sum():.9g} - discharged {product_dem.sum():.9g} = "
                          f"{held0.sum() + Fd.sum() - product_dem.sum():.9g} kg, but "
                          f"{held1.sum():.9g} kg held at {T1:.6g} s")
    budget = held1 - held0 - (Fd + P.sum(axis=1) - B - D)
    budget[F] = product_dem[F] - P[F].sum()  # the fines: all their progeny leaves
    worst = int(np.argmax(np.abs(budget)))
    if abs(budget[worst]) > BALANCE_TOLERANCE * scale:
        raise Bookkeeping(f"class {worst} [{edges[worst + 1]:.4g}, {edges[worst]:.4g}) m: held "
                          f"change - fed - progeny + broken + discharged = {budget[worst]:.3g} kg")
    st = run.series["time"]
    r0 = np.nonzero(np.abs(st - T0) <= 1e-12 * max(1.0, T0))[0]
    r1 = np.nonzero(np.abs(st - T1) <= 1e-12 * max(1.0, T1))[0]
    if len(r0) and len(r1):
        r0, r1 = r0[-1], r1[-1]
        ser = run.series
        for what, mine, theirs in (
                ("ore held at T0 (series ore_mass)", held0.sum(), ser["ore_mass"][r0]),
                ("ore held at T1 (series ore_mass)", held1.sum(), ser["ore_mass"][r1]),
                ("fed in the window (series fed_mass)", Fd.sum(),
                 ser["fed_mass"][r1] - ser["fed_mass"][r0]),
                ("discharged in the window (series discharged_mass)", product_dem.sum(),
                 ser["discharged_mass"][r1] - ser["discharged_mass"][r0])):
            if abs(mine - theirs) > BALANCE_TOLERANCE * scale:
                raise Bookkeeping(f"{what}: {theirs!r} kg, the particles give {mine!r} kg")
    else:
        notes.append("series.csv has no rows at the window's snapshots: not checked against it")
    check_sizes(run, fed, removed)

    # ---- parameters ----
    with np.errstate(divide="ignore", invalid="ignore"):
        S = np.where(mbar > 0, net / (mbar * T), np.where(net > 0, np.inf, 0.0))
        d = np.where(mbar > 0, D / (mbar * T), np.where(D > 0, np.inf, 0.0))
    S[F], d[F] = 0.0, np.inf
    f = Fd / T
    instant = ~np.isfinite(S) | ~np.isfinite(d)
    with np.errstate(divide="ignore", invalid="ignore"):
        split = np.where(net + D > 0, net / (net + D), 0.0)
    split[F] = 0.0
    Sf = np.where(np.isfinite(S), S, 0.0)
    dfin = np.where(np.isfinite(d), d, 0.0)

    # Collisions over the whole run.
    def count_held(lo, hi):
        c = [np.count_nonzero((2.0 * r >= lo) & (2.0 * r < hi)) for r in run.radii]
        return float(time_average(times, np.array(c, dtype=float)[:, None])[0])
    spec = spectra_classes(run, edges, count_held)
    if spec is None:
        coll_e, coll_n = np.full(n, np.nan), np.full(n, np.nan)
        notes.append("no collisions.csv (run with output.collision_spectra = true): "
                     "the collision columns are nan")
    else:
        coll_e, coll_n, left_out, spectra_bins = spec
        aligned = all(x in edges or not (edges[-2] < x < edges[0])
                      for lo, hi in spectra_bins for x in (lo, hi))
        notes.append("collisions: spectra classes " +
                     ("aligned with the PBM edges (exact)" if aligned else
                      "shared among the PBM classes by the particles held") +
                     f"; over [0, {t_end:.6g}] s" +
                     (f"; {left_out:.4g} J above the top edge left out" if left_out > 0 else ""))
    with np.errstate(divide="ignore", invalid="ignore"):
        power = np.where(mbar_run > 0, coll_e / (mbar_run * t_end), np.nan)
        mean_e = np.where(coll_n > 0, coll_e / coll_n, np.nan)

    # ---- forward model ----
    m_end, prod, hist_t, hist_m, h = forward(held0, f, Sf, dfin, bmat, T, a.dt, instant, split)
    drift = held0.sum() + f.sum() * T - prod.sum() - m_end.sum()
    if abs(drift) > 1e-9 * scale:
        raise Bookkeeping(f"the forward model lost {drift:.3g} kg (a bug in pbm.py)")

    # ---- files ----
    out = a.output or os.path.join(a.outdir, "pbm.csv")
    stem = out[:-4] if out.endswith(".csv") else out
    bout, fout = stem + "_breakage.csv", stem + "_forward.csv"
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    g = lambda x: repr(float(x))  # noqa: E731  (inf, nan as Python writes them)
    with open(out, "w", encoding="ascii", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["i", "d_lo", "d_hi", "held_kg", "S_per_s", "d_per_s", "feed_kg_s",
                    "specific_collision_power_W_kg", "collisions", "mean_collision_energy_J",
                    "held_run_kg", "broken_kg", "broken_net_kg", "discharged_kg", "fed_kg",
                    "held_start_kg", "held_end_kg", "t0", "t1"])
        for i in range(n):
            w.writerow([i, g(edges[i + 1]), g(edges[i]), g(mbar[i]), g(S[i]), g(d[i]), g(f[i]),
                        g(power[i]), g(coll_n[i]), g(mean_e[i]), g(mbar_run[i]), g(B[i]),
                        g(net[i]), g(product_dem[i]), g(Fd[i]), g(held0[i]), g(held1[i]),
                        g(T0), g(T1)])
    with open(bout, "w", encoding="ascii", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["i", "j", "b_ij", "d_lo_i", "d_hi_i", "d_lo_j", "d_hi_j"])
        for j in range(n):
            for i in range(j + 1, n):
                w.writerow([i, j, g(bmat[i, j]), g(edges[i + 1]), g(edges[i]), g(edges[j + 1]),
                            g(edges[j])])
    pp_dem, pp_pbm = passing(product_dem), passing(prod)
    mp_dem, mp_pbm = passing(held1), passing(m_end)
    with open(fout, "w", encoding="ascii", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["i", "d_lo", "d_hi", "product_dem_kg", "product_pbm_kg", "product_dem_passing",
                    "product_pbm_passing", "mill_dem_kg", "mill_pbm_kg", "mill_dem_passing",
                    "mill_pbm_passing"])
        for i in range(n):
            w.writerow([i, g(edges[i + 1]), g(edges[i]), g(product_dem[i]), g(prod[i]),
                        g(pp_dem[i]), g(pp_pbm[i]), g(held1[i]), g(m_end[i]), g(mp_dem[i]),
                        g(mp_pbm[i])])

    # ---- report ----
    print(f"PBM of {a.outdir}: window {T0:.6g}-{T1:.6g} s ({s1 - s0 + 1} snapshots), "
          f"{n} classes (ratio {a.classes:.6g} from {top:.6g} m, "
          f"{'fines below' if run.has_fines else 'no fines: bottom edge the smallest ore,'} "
          f"{run.fines:.6g} m), "
          f"{int(bw.sum())} breaks, {int(pw.sum())} particles discharged, {len(fed_r)} fed; "
          f"implicit Euler, dt {h:.3g} s")
    for note in notes:
        print(f"  note: {note}")
    print(f"{'i':>2} {'d_lo mm':>8} {'d_hi mm':>8} {'held kg':>9} {'S 1/s':>8} {'d 1/s':>8} "
          f"{'feed kg/s':>9} {'coll W/kg':>9} {'collisions':>10} {'E/coll J':>9}")
    for i in range(n):
        print(f"{i:>2} {1e3 * edges[i + 1]:8.2f} {1e3 * edges[i]:8.2f} {mbar[i]:9.3f} {S[i]:8.4g} "
              f"{d[i]:8.4g} {f[i]:9.4g} {power[i]:9.4g} {coll_n[i]:10.1f} {mean_e[i]:9.3g}")
    print(f"{'i':>2} {'d_hi mm':>8} | {'product kg DEM':>14} {'PBM':>8} {'pass% DEM':>9} "
          f"{'PBM':>7} | {'mill kg DEM':>11} {'PBM':>8} {'pass% DEM':>9} {'PBM':>7}")
    for i in range(n):
        print(f"{i:>2} {1e3 * edges[i]:8.2f} | {product_dem[i]:14.4f} {prod[i]:8.4f} "
              f"{pp_dem[i]:9.3f} {pp_pbm[i]:7.3f} | {held1[i]:11.4f} {m_end[i]:8.4f} "
              f"{mp_dem[i]:9.3f} {mp_pbm[i]:7.3f}")
    if product_dem.sum() > 0:
        dp = float(np.nanmax(np.abs(pp_dem - pp_pbm)))
        rel = 100.0 * (prod.sum() - product_dem.sum()) / product_dem.sum()
    else:
        dp, rel = 0.0, 0.0
    dm = float(np.nanmax(np.abs(mp_dem - mp_pbm))) if held1.sum() > 0 else 0.0
    ok = dp <= PRODUCT_TOLERANCE and abs(rel) <= TOTAL_TOLERANCE
    half = T0 + 0.5 * T
    first = float(br["mass"][bw & (br["time"] <= half)].sum())
    second = float(br["mass"][bw & (br["time"] > half)].sum())
    print(f"  broken in the window's halves: {first:.4g} kg, {second:.4g} kg (the PBM's constant "
          f"rates spread them evenly: the more they differ, the larger the mean-field error)")
    print(f"summary: product DEM {product_dem.sum():.4g} kg, PBM {prod.sum():.4g} kg "
          f"({rel:+.2f} %, tolerance {TOTAL_TOLERANCE:g} %); mill at {T1:.6g} s DEM "
          f"{held1.sum():.4g} kg, PBM {m_end.sum():.4g} kg; max |passing difference| product "
          f"{dp:.2f} % (tolerance {PRODUCT_TOLERANCE:g} %), mill {dm:.2f} %: "
          f"{'consistent' if ok else 'OUTSIDE the tolerance'}")
    print(f"wrote {out}, {bout}, {fout}" + (f", {a.plot}" if a.plot else ""))
    if a.plot:
        plot(a.plot, edges, product_dem, prod, held1, m_end, S, d, run, s0, s1, hist_t + T0,
             hist_m, T0)
    if not ok:
        print(f"pbm.py: the forward model's product misses the DEM's: {dp:.2f} % passing "
              f"(tolerance {PRODUCT_TOLERANCE:g} %), {rel:+.2f} % in mass (tolerance "
              f"{TOTAL_TOLERANCE:g} %); a window from where breakage is under way (--window) "
              "takes the start-up out", file=sys.stderr)
        return 2
    return 0


def check_sizes(run, fed, removed):
    """Over the whole run, sizes.csv against the particles (1e-6 of the masses involved)."""
    sz = run.sizes
    k_of_row = np.rint(4.0 * np.log2(np.where(np.isfinite(sz["diameter"]), sz["diameter"], 1e300)
                                     / 1e-6)).astype(int)
    k_of_row = np.where(np.isfinite(sz["diameter"]), k_of_row, 95)
    nclass = 96

    def by_class(column):
        out = np.zeros(nclass)
        np.add.at(out, k_of_row, sz[column])
        return out

    def particles(diameters, masses):
        out = np.zeros(nclass)
        if len(diameters):
            np.add.at(out, quarter_octave_class(diameters), masses)
        return out

    fed_r = np.array([r for r, _ in fed.values()])
    fines = float(run.breaks["fines_mass"].sum())
    checks = [
        ("initial_mass", particles(2.0 * run.radii[0], run.masses[0]), None),
        ("mill_mass", particles(2.0 * run.radii[-1], run.masses[-1]), None),
        ("fed_mass", particles(2.0 * fed_r, sphere_mass(fed_r, run.density)), None),
        ("product_mass", particles(2.0 * run.product["radius"], run.product["mass"]), fines),
    ]
    for column, mine, fines_mass in checks:
        theirs = by_class(column)
        scale = max(theirs.sum(), mine.sum(), 1e-300)
        if fines_mass is None:
            worst = int(np.argmax(np.abs(theirs - mine)))
            if abs(theirs[worst] - mine[worst]) > BALANCE_TOLERANCE * scale:
                lo = 1e-6 * 2 ** (0.25 * (worst - 1))
                raise Bookkeeping(f"sizes.csv {column}: {theirs[worst]!r} kg in the class from "
                                  f"{lo:.6g} m, the particles give {mine[worst]!r} kg")
        else:
            # The fines are spread below fines_diameter: compare the cumulative masses above it.
            cum_t, cum_m = np.cumsum(theirs), np.cumsum(mine) + fines_mass
            ks = [k for k in range(nclass) if 1e-6 * 2 ** (0.25 * k) > run.fines]
            bad = [k for k in ks if abs(cum_t[k] - cum_m[k]) > BALANCE_TOLERANCE * scale]
            if bad:
                k = bad[0]
                raise Bookkeeping(f"sizes.csv {column}: {cum_t[k]!r} kg below "
                                  f"{1e-6 * 2 ** (0.25 * k):.6g} m, product.csv and the fines "
                                  f"give {cum_m[k]!r} kg")


def plot(path, edges, product_dem, prod, held1, m_end, S, d, run, s0, s1, hist_t, hist_m, T0):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = len(edges) - 1
    hi = edges[:-1] * 1e3
    fig, ax = plt.subplots(2, 2, figsize=(12, 8))
    for p, dem, pbm, title in ((ax[0, 0], product_dem, prod, "product over the window"),
                               (ax[0, 1], held1, m_end, "mill at the window's end")):
        p.semilogx(hi, passing(dem), "o-", label=f"DEM ({dem.sum():.4g} kg)")
        p.semilogx(hi, passing(pbm), "s--", label=f"PBM ({pbm.sum():.4g} kg)")
        p.set_xlabel("class upper edge [mm]")
        p.set_ylabel("cumulative % passing")
        p.set_title(title)
        p.grid(True, which="both", alpha=0.3)
        p.legend()
    p = ax[1, 0]
    mid = np.sqrt(edges[:-2] * edges[1:-1]) * 1e3
    p.loglog(mid, np.where(S[:-1] > 0, S[:-1], np.nan), "o-", label="S (broken out, 1/s)")
    p.loglog(mid, np.where((d[:-1] > 0) & np.isfinite(d[:-1]), d[:-1], np.nan), "s-",
             label="d (discharged, 1/s)")
    p.set_xlabel("class mid-size [mm]")
    p.set_ylabel("rate [1/s]")
    p.set_title(f"selection and discharge ({n - 1} classes above the fines)")
    p.grid(True, which="both", alpha=0.3)
    p.legend()
    p = ax[1, 1]
    p.plot(run.times[s0:s1 + 1], [m.sum() for m in run.masses[s0:s1 + 1]], "o",
           label="DEM (snapshots)")
    p.plot(hist_t, hist_m, "-", label="PBM")
    p.set_xlabel("time [s]")
    p.set_ylabel("ore in the mill [kg]")
    p.set_title("hold-up")
    p.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
