#!/usr/bin/python3
"""Events per particle-step and per contact from two cachegrind runs of bench/throughput's
--profile-* modes (bench/profile_contacts.sh runs them).

    post/profile_contacts.py [--csv OUT.csv] [--top 8] SCENE LO_BASE HI_BASE [SCENE LO HI ...]

LO_BASE / HI_BASE: the runs with fewer / more profiled steps; BASE.cg.out is cachegrind's file
(run with --cache-sim=yes --branch-sim=yes), BASE.txt holds the program's line
"profile ...: particles P steps S particle_steps X contact_steps C candidate_steps K".
Everything is the difference HI - LO: the set-up and warm-up, identical in both, cancel.

CSV rows (one schema): scene, kind, name, the events Ir Dr Dw D1mr D1mw DLmr DLmw Bc Bcm Bi
Bim, share_Ir, then particles, steps, contacts_per_particle, candidates_per_particle;
kind = per_particle_step | per_contact (name empty) | function (events per contact of one
function, share_Ir its share of all instructions; the top functions by instructions).
Events: Ir instructions; Dr, Dw data reads, writes; D1mr, D1mw L1 data read, write misses;
DLmr, DLmw last-level read, write misses; Bc, Bcm conditional branches and their
mispredictions; Bi, Bim indirect branches and their mispredictions (cachegrind's simulation:
caches as detected on the host, a simple branch predictor).
"""

import argparse
import collections
import csv
import os
import re
import sys

EVENTS = ["Ir", "Dr", "Dw", "D1mr", "D1mw", "DLmr", "DLmw", "Bc", "Bcm", "Bi", "Bim"]


def read_cg(path):
    """Totals and per-function sums of a cachegrind out file: (events, desc, totals, per_fn)."""
    events, desc, per_fn, summary = None, [], collections.defaultdict(lambda: None), None
    fn = None
    with open(path) as f:
        for line in f:
            if line.startswith("desc:"):
                desc.append(line[5:].strip())
            elif line.startswith("events:"):
                events = line.split()[1:]
            elif line.startswith("fn="):
                fn = line[3:].rstrip("\n")
            elif line.startswith("fl="):
                continue
            elif line.startswith("summary:"):
                summary = [int(v) for v in line.split()[1:]]
            elif line and line[0].isdigit() and fn is not None:
                vals = [int(v) for v in line.split()[1:]]
                acc = per_fn[fn]
                if acc is None:
                    acc = [0] * len(events)
                    per_fn[fn] = acc
                for k, v in enumerate(vals):
                    acc[k] += v
    if events is None or summary is None:
        sys.exit(f"profile_contacts: {path} is not a cachegrind file")
    summary += [0] * (len(events) - len(summary))
    to_dict = lambda vals: {e: (vals[events.index(e)] if e in events else 0) for e in EVENTS}
    return desc, to_dict(summary), {k: to_dict(v) for k, v in per_fn.items()}


def read_counts(path):
    with open(path) as f:
        text = f.read()
    m = re.search(r"particles (\S+) steps (\S+) particle_steps (\S+) contact_steps (\S+) "
                  r"candidate_steps (\S+)", text)
    if not m:
        sys.exit(f"profile_contacts: no 'profile' line in {path}")
    return [float(v) for v in m.groups()]


def short(name, width=70):
    """The function's name without template arguments and parameters: Kernel<>::gather()."""
    name = re.sub(r"std::experimental::parallelism_v2::", "stdx::", name)
    prev = None
    while prev != name:
        prev = name
        name = re.sub(r"<[^<>]*>", "<>", name)
        name = re.sub(r"\([^()]*\)", "()", name)
    return name if len(name) <= width else "..." + name[-(width - 3):]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--csv", default=None)
    ap.add_argument("--top", type=int, default=8)
    ap.add_argument("runs", nargs="+", help="SCENE LO_BASE HI_BASE, repeated")
    a = ap.parse_args()
    if len(a.runs) % 3:
        sys.exit("profile_contacts: arguments come in threes: SCENE LO_BASE HI_BASE")
    rows, tables = [], []
    desc_shown = False
    for k in range(0, len(a.runs), 3):
        scene, lo, hi = a.runs[k : k + 3]
        desc, tot_lo, fn_lo = read_cg(lo + ".cg.out")
        _, tot_hi, fn_hi = read_cg(hi + ".cg.out")
        c_lo, c_hi = read_counts(lo + ".txt"), read_counts(hi + ".txt")
        particles = c_hi[0]
        steps = c_hi[1] - c_lo[1]
        psteps = c_hi[2] - c_lo[2]
        contacts = c_hi[3] - c_lo[3]
        cands = c_hi[4] - c_lo[4]
        d = {e: tot_hi[e] - tot_lo[e] for e in EVENTS}
        meta = dict(particles=int(particles), steps=int(steps),
                    contacts_per_particle=contacts / psteps, candidates_per_particle=cands / psteps)
        if not desc_shown:
            print("cachegrind's simulated machine: " + "; ".join(desc))
            desc_shown = True
        per_ps = {e: d[e] / psteps for e in EVENTS}
        per_c = {e: d[e] / contacts for e in EVENTS}
        rows.append(dict(scene=scene, kind="per_particle_step", name="", share_Ir="", **per_ps, **meta))
        rows.append(dict(scene=scene, kind="per_contact", name="", share_Ir="", **per_c, **meta))
        fns = {}
        for name in set(fn_hi) | set(fn_lo):
            z = {e: 0 for e in EVENTS}
            h, l = fn_hi.get(name, z), fn_lo.get(name, z)
            fns[name] = {e: h[e] - l[e] for e in EVENTS}
        top = sorted(fns.items(), key=lambda kv: -kv[1]["Ir"])[: a.top]
        for name, ev in top:
            rows.append(dict(scene=scene, kind="function", name=name, share_Ir=ev["Ir"] / d["Ir"],
                             **{e: ev[e] / contacts for e in EVENTS}, **meta))
        tables.append((scene, meta, per_ps, per_c, top, d))

    print()
    print(f"{'scene':9} {'per':14} {'Ir':>8} {'Dr':>7} {'Dw':>7} {'D1mr':>7} {'D1mw':>7} {'LLmr':>7} "
          f"{'LLmw':>7} {'Bc':>7} {'Bcm':>7} {'Bi':>6} {'Bim':>6}")
    for scene, meta, per_ps, per_c, _, _ in tables:
        for label, ev in (("particle-step", per_ps), ("contact", per_c)):
            print(f"{scene:9} {label:14} {ev['Ir']:8.1f} {ev['Dr']:7.1f} {ev['Dw']:7.1f} "
                  f"{ev['D1mr']:7.3f} {ev['D1mw']:7.3f} {ev['DLmr']:7.4f} {ev['DLmw']:7.4f} "
                  f"{ev['Bc']:7.2f} {ev['Bcm']:7.3f} {ev['Bi']:6.3f} {ev['Bim']:6.4f}")
        print(f"{'':9} ({meta['particles']} particles, {meta['steps']} steps differenced, "
              f"{meta['contacts_per_particle']:.3f} contacts and {meta['candidates_per_particle']:.3f} "
              "candidate pairs per particle-step)")
    for scene, meta, _, _, top, d in tables:
        print(f"\n{scene}: top functions by instructions (per contact; share of all)")
        for name, ev in top:
            print(f"  {100 * ev['Ir'] / d['Ir']:5.1f} %  Ir {ev['Ir'] / (meta['contacts_per_particle'] * meta['particles'] * meta['steps']):7.1f}"
                  f"  D1mr {ev['D1mr'] / (meta['contacts_per_particle'] * meta['particles'] * meta['steps']):6.3f}"
                  f"  Bcm {ev['Bcm'] / (meta['contacts_per_particle'] * meta['particles'] * meta['steps']):6.3f}  {short(name)}")
    if a.csv:
        os.makedirs(os.path.dirname(os.path.abspath(a.csv)), exist_ok=True)
        fields = ["scene", "kind", "name"] + EVENTS + ["share_Ir", "particles", "steps",
                                                       "contacts_per_particle", "candidates_per_particle"]
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            for r in rows:
                w.writerow(r)
        print(f"\nwrote {a.csv}")


if __name__ == "__main__":
    main()
