#!/usr/bin/python3
"""Plot and summarise an ore run: size distributions, ore in the mill, mass balance, steady state.

What the mill ground, and its feed, discharge and specific energy once it runs steadily.

    post/plot_grinding.py OUTDIR [-o grinding.png] [--window S] [--json FILE]

Reads from OUTDIR: series.csv, product.csv (every particle the discharge let out),
breakages.csv (every break, with the fines it sent out as product), sizes.csv (the size
distributions by mass), run.json (the deck, F80, P80 and the slice caveat of specific energies)
and snapshots.h5 (the ore in the mill). Six panels:
  (a) cumulative % passing against diameter (mm, log) of the ore at the start, the ore fed, the
      product (fines included) and the mill contents at the end, from sizes.csv, with the
      aperture, F80 and P80 (run.json's) marked (the curves join the passing at the class
      edges; F80 and P80 are read within a class between the sizes in it, so a mark may sit
      a little off its curve);
  (b) the ore in the mill at several snapshot times: cumulative % passing against diameter;
  (c) counts against time: breakages, fragments born, particles fed and discharged;
  (d) masses against time: ore in the mill, fed, discharged (fines included), and the
      mass-balance error mill_mass[0] + fed - mill_mass - discharged (right axis);
  (e) feed and discharge rates against time, the steady-state window shaded;
  (f) the steady-state figures over the window (default the last third of the run): feed and
      discharge rates, ore hold-up and its change, mean drive power, specific energy.

The ore is the material named by the deck's [breakage] (else [feed], else [sieve]) in run.json,
found by name in snapshots.h5's /materials (else in run.json's material list).

Steady-state window [t_end - S, t_end] (rows of series.csv in it, the first and last row r0, r1):
  feed rate       = (fed_mass[r1] - fed_mass[r0]) / (time[r1] - time[r0])            [kg/s]
  discharge rate  = (discharged_mass[r1] - discharged_mass[r0]) / (same)            [kg/s]
  hold-up         = mean of ore_mass over the window's rows                          [kg]
  hold-up change  = (mean over the second half - mean over the first half) / first, the halves
                    split at the window's middle time (a steady mill: near 0)
  power           = (drum_work[r1] - drum_work[r0]) / (same)                          [W]
  specific energy = power / discharge rate / 3600        [kWh per tonne of product]
Every kWh/t figure carries run.json's note on what a 2D slice's specific energy means.

Prints one line per figure, `name = value [unit]  (comment)`, and with --json writes the same
numbers to FILE. The product mass printed is product.csv's masses plus breakages.csv's
fines_mass; a warning goes to stderr when it differs from run.json's product mass or series.csv's
last discharged_mass by more than 1e-9 relative. F80, P80 and the reduction ratio are run.json's.
"""

import argparse
import csv
import json
import math
import os
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import h5py  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402
import numpy as np  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ beside the installed scripts
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import millplot  # noqa: E402
from snapshot_order import snapshot_names  # noqa: E402

BALANCE_TOLERANCE = 1e-9  # relative: the product mass from the files against run.json's
STREAMS = [("initial", "ore at the start", "tab:gray"), ("fed", "ore fed", "tab:blue"),
           ("product", "product (fines included)", "tab:red"),
           ("mill", "mill contents at the end", "tab:green")]


# --- Reading -------------------------------------------------------------------------------------

def read_csv(path):
    """A CSV as {column: array}: floats where every value parses (`nan` included), strings
    otherwise (series.csv's `regime`); empty float arrays for a header-only file. A truncated
    last row (a run killed mid-write) is dropped."""
    with open(path, encoding="ascii", newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None) or []
        rows = [row for row in reader if len(row) == len(header)]
    columns = list(zip(*rows)) if rows else [()] * len(header)
    out = {}
    for name, values in zip(header, columns):
        try:
            out[name] = np.array(values, dtype=float)
        except ValueError:
            out[name] = np.array(values, dtype=str)
    return out


def material_names(h5_path):
    """The material names in /materials of snapshots.h5 in index order ([] when absent)."""
    if not h5_path or not os.path.exists(h5_path):
        return []
    with h5py.File(h5_path, "r") as f:
        if "materials" not in f or "name" not in f["materials"]:
            return []
        return [n.decode() if isinstance(n, bytes) else str(n) for n in f["materials/name"][:]]


def ore_material(run, h5_path=None):
    """(index, name, where the index came from) of the ore: the material named by the deck's
    [breakage], else [feed], else [sieve] (run.json), looked up in snapshots.h5's /materials,
    else in run.json's material list. (None, name or None, reason) when it cannot be found."""
    deck = millplot.deck_of(run)
    name = None
    for table in ("breakage", "feed", "sieve"):
        section = deck.get(table)
        if isinstance(section, dict) and section.get("material"):
            name = str(section["material"])
            break
    if name is None:
        return None, None, "run.json names no ore material ([breakage], [feed] or [sieve])"
    names = material_names(h5_path)
    if name in names:
        return names.index(name), name, "snapshots.h5 /materials"
    listed = [m.get("name") for m in deck.get("material", []) if isinstance(m, dict)]
    if name in listed:
        return listed.index(name), name, "run.json deck.material"
    return None, name, f"material '{name}' is in neither snapshots.h5 nor run.json"


def ore_in_mill(h5_path, ore_index, count=5):
    """[(time, diameters [m], masses [kg])] of the ore in `count` snapshots spread over the run,
    in time order (masses from /materials/density; proportional to d^3 without it)."""
    out = []
    with h5py.File(h5_path, "r") as f:
        keys = snapshot_names(f)
        density = 1.0
        if "materials" in f and "density" in f["materials"]:
            density = float(f["materials/density"][ore_index])
        picks = np.linspace(0, len(keys) - 1, min(count, len(keys))).astype(int)
        for key in [keys[i] for i in picks]:
            g = f["snapshots"][key]
            d = 2.0 * g["radius"][:][g["material"][:] == ore_index]
            out.append((float(g.attrs["time"]), d, density * np.pi / 6.0 * d ** 3))
    return out


def cumulative(size, mass):
    """Sizes sorted and the cumulative mass passing (%) at each."""
    order = np.argsort(size)
    m = np.cumsum(mass[order])
    return size[order], 100.0 * m / m[-1]


def number(value):
    """A float from run.json (nan when absent or not a number)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


# --- The figures ---------------------------------------------------------------------------------

def product_mass(product, breakages):
    """(particles [kg], fines [kg]): product.csv's masses and breakages.csv's fines_mass."""
    particles = float(np.sum(product.get("mass", np.zeros(0))))
    fines = float(np.sum(breakages.get("fines_mass", np.zeros(0))))
    return particles, fines


def window_figures(series, window=None):
    """The steady-state figures over the last `window` seconds (default: the last third of the
    run), as a dict (see the module's docstring for the definitions)."""
    t = series["time"]
    span = float(t[-1] - t[0])
    length = span / 3.0 if window is None else min(float(window), span)
    r0 = int(np.searchsorted(t, t[-1] - length, side="left"))
    r1 = len(t) - 1
    r0 = min(r0, r1 - 1) if r1 > 0 else 0
    dt = float(t[r1] - t[r0])
    work = series.get("drum_work", series.get("drive_work"))

    def rate(column):
        return float((column[r1] - column[r0]) / dt) if dt > 0 else float("nan")

    tt, hold = t[r0:r1 + 1], series["ore_mass"][r0:r1 + 1]
    middle = 0.5 * (t[r0] + t[r1])
    first, second = hold[tt < middle], hold[tt >= middle]
    m1 = float(np.mean(first)) if first.size else float("nan")
    m2 = float(np.mean(second)) if second.size else float("nan")
    feed, discharge = rate(series["fed_mass"]), rate(series["discharged_mass"])
    power = rate(work) if work is not None else float("nan")
    return {
        "window_start_s": float(t[r0]),
        "window_end_s": float(t[r1]),
        "window_rows": r1 - r0 + 1,
        "window_feed_rate_kg_s": feed,
        "window_discharge_rate_kg_s": discharge,
        "window_holdup_mean_kg": float(np.mean(hold)),
        "window_holdup_first_half_kg": m1,
        "window_holdup_second_half_kg": m2,
        "window_holdup_change": (m2 - m1) / m1 if m1 > 0 else float("nan"),
        "window_power_W": power,
        "window_specific_energy_kwh_per_t":
            power / discharge / 3600.0 if discharge > 0 else float("nan"),
    }


def summary(outdir, window=None):
    """Everything the script prints and plots, read from OUTDIR: (figures, data)."""
    run = millplot.read_run_json(outdir)
    series = read_csv(os.path.join(outdir, "series.csv"))
    if "time" not in series or len(series["time"]) < 2:
        raise ValueError(f"{outdir}/series.csv: fewer than two rows")
    for column in ("fed_mass", "discharged_mass", "ore_mass", "mill_mass"):
        if column not in series:
            raise ValueError(f"{outdir}/series.csv has no {column} column: not an ore scene")
    product = read_csv(os.path.join(outdir, "product.csv"))
    breakages = read_csv(os.path.join(outdir, "breakages.csv"))
    sizes_path = os.path.join(outdir, "sizes.csv")
    sizes = read_csv(sizes_path) if os.path.exists(sizes_path) else {}
    grinding = run.get("grinding", {}) if isinstance(run.get("grinding"), dict) else {}
    particles, fines = product_mass(product, breakages)
    m0 = series["mill_mass"][0]
    err = m0 + series["fed_mass"] - series["mill_mass"] - series["discharged_mass"]
    figures = {
        "breakages": len(breakages.get("time", [])),
        "product_mass_kg": particles + fines,
        "product_particles_kg": particles,
        "product_fines_kg": fines,
        "product_particles": len(product.get("time", [])),
        "feed": grinding.get("feed", "unknown"),
        "f80_m": number(grinding.get("f80_m")),
        "p80_m": number(grinding.get("p80_m")),
        "mill_p80_m": number(grinding.get("mill_p80_m")),
        "reduction_ratio": number(grinding.get("reduction_ratio")),
        "run_time_s": float(series["time"][-1]),
        "run_specific_energy_kwh_per_t": number(grinding.get("specific_energy_kwh_per_t")),
        "mass_balance_error_kg": float(np.max(np.abs(err))),
        "mass_balance_error_relative": float(np.max(np.abs(err)) / m0) if m0 > 0 else 0.0,
    }
    figures.update(window_figures(series, window))
    figures["specific_energy_note"] = grinding.get(
        "specific_energy_note", "a 2D slice's figure (run.json gives no note)")
    data = {"run": run, "series": series, "product": product, "breakages": breakages,
            "sizes": sizes, "balance_error": err, "grinding": grinding}
    return figures, data


def consistency_warnings(figures, data):
    """Where the product mass from the files disagrees with run.json or series.csv."""
    warnings = []
    mine = figures["product_mass_kg"]
    for what, other in [("run.json grinding.product_mass_kg",
                         number(data["grinding"].get("product_mass_kg"))),
                        ("series.csv discharged_mass at the end",
                         float(data["series"]["discharged_mass"][-1]))]:
        if math.isnan(other):
            continue
        if abs(mine - other) > BALANCE_TOLERANCE * max(abs(mine), abs(other), 1e-300):
            warnings.append(f"product mass {mine:.10g} kg (product.csv + fines) differs from "
                            f"{what} {other:.10g} kg")
    count = data["series"]["breakages"][-1] if "breakages" in data["series"] else None
    if count is not None and int(count) != figures["breakages"]:
        warnings.append(f"breakages.csv has {figures['breakages']} rows, series.csv counts "
                        f"{int(count)}")
    return warnings


def ratio(f):
    """The window's discharge rate / feed rate as text (1 at steady state)."""
    feed = f["window_feed_rate_kg_s"]
    return f"{f['window_discharge_rate_kg_s'] / feed:.3g}" if feed > 0 else "no feed"


def summary_lines(f):
    """The printed summary: one `name = value [unit]  (comment)` line per figure."""
    note = f["specific_energy_note"]
    g = lambda x: f"{x:.10g}"  # noqa: E731
    return [
        f"breakages = {f['breakages']}",
        f"product_mass_kg = {g(f['product_mass_kg'])} kg  (product.csv {f['product_particles']} "
        f"particles {g(f['product_particles_kg'])} kg + fines {g(f['product_fines_kg'])} kg)",
        f"f80_m = {g(f['f80_m'])} m  (run.json; feed: {f['feed']})",
        f"p80_m = {g(f['p80_m'])} m  (run.json; the product, fines included)",
        f"reduction_ratio = {g(f['reduction_ratio'])}  (run.json; F80 / P80)",
        f"window_s = {g(f['window_end_s'] - f['window_start_s'])} s  "
        f"(t = {f['window_start_s']:.6g} .. {f['window_end_s']:.6g} s, {f['window_rows']} rows)",
        f"window_feed_rate_kg_s = {g(f['window_feed_rate_kg_s'])} kg/s",
        f"window_discharge_rate_kg_s = {g(f['window_discharge_rate_kg_s'])} kg/s  "
        f"(particles and fines; {ratio(f)} of the feed rate, 1 at steady state)",
        f"window_holdup_mean_kg = {g(f['window_holdup_mean_kg'])} kg  (ore in the mill)",
        f"window_holdup_change = {g(f['window_holdup_change'])}  "
        f"({100 * f['window_holdup_change']:+.3g} %: second half of the window against the first)",
        f"window_power_W = {g(f['window_power_W'])} W  (drum work / window)",
        f"window_specific_energy_kwh_per_t = {g(f['window_specific_energy_kwh_per_t'])} kWh/t  "
        f"(of product, power / discharge rate; {note})",
        f"run_specific_energy_kwh_per_t = {g(f['run_specific_energy_kwh_per_t'])} kWh/t  "
        f"(run.json, whole run's drum work / product; {note})",
        f"mass_balance_error_kg = {f['mass_balance_error_kg']:.3g} kg  "
        f"({f['mass_balance_error_relative']:.3g} of the initial mill mass)",
    ]


# --- Drawing -------------------------------------------------------------------------------------

def log_diameter_axis(ax):
    """A log x axis of diameters in mm, its ticks as plain numbers (20, 50, 100)."""
    ax.set_xscale("log")
    plain = FuncFormatter(lambda v, _: f"{v:g}")
    ax.xaxis.set_major_formatter(plain)
    ax.xaxis.set_minor_formatter(FuncFormatter(
        lambda v, _: f"{v:g}" if f"{v:g}"[0] in "25" else ""))
    ax.set_xlabel("diameter [mm]")


def mark_aperture(ax, aperture):
    if aperture:
        ax.axvline(1e3 * aperture, color="k", linestyle="--", linewidth=0.9,
                   label=f"aperture {1e3 * aperture:.3g} mm")


def plot_sizes(ax, f, data, aperture):
    """(a) cumulative % passing of each stream against diameter, F80 and P80 marked."""
    sizes = data["sizes"]
    smallest = []  # per stream: the finest size with 0.5 % passing (the x axis starts there)
    if sizes:
        d = 1e3 * sizes["diameter"]
        for stream, label, color in STREAMS:
            mass = sizes.get(f"{stream}_mass")
            if mass is None or not np.sum(mass) > 0:
                continue
            keep = np.cumsum(mass) > 0  # from the first class that holds mass
            first = max(int(np.argmax(keep)) - 1, 0)
            ax.plot(d[first:], sizes[f"{stream}_passing"][first:], color=color, marker=".",
                    markersize=3, label=f"{label}: {np.sum(mass):.4g} kg")
            smallest.append(d[int(np.argmax(sizes[f"{stream}_passing"] >= 0.5))])
    elif len(data["product"].get("radius", [])):  # no sizes.csv: the product's particles
        dd, c = cumulative(2e3 * data["product"]["radius"], data["product"]["mass"])
        ax.plot(dd, c, drawstyle="steps-post", color="tab:red", label="product particles")
    mark_aperture(ax, aperture)
    ax.axhline(80.0, color="0.6", linestyle=":", linewidth=0.8)
    for key, label, color in [("f80_m", "F80", "tab:blue"), ("p80_m", "P80", "tab:red")]:
        if math.isfinite(f[key]):
            ax.plot(1e3 * f[key], 80.0, marker="o", color=color, markersize=7,
                    markerfacecolor="none", markeredgewidth=1.5,
                    label=f"{label} = {1e3 * f[key]:.4g} mm")
    log_diameter_axis(ax)
    if smallest:
        ax.set_xlim(left=0.5 * min(smallest))
    ax.set_ylabel("cumulative mass passing [%]")
    ax.set_ylim(0, 102)
    ax.set_title(f"(a) size distributions (sizes.csv); reduction ratio F80/P80 = "
                 f"{f['reduction_ratio']:.3g}", fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, which="both", alpha=0.3)


def plot_ore_in_mill(ax, outdir, run, aperture):
    """(b) the ore in the mill at several snapshot times."""
    h5 = os.path.join(outdir, "snapshots.h5")
    index, name, source = ore_material(run, h5)
    if not os.path.exists(h5) or index is None:
        why = "no snapshots.h5" if not os.path.exists(h5) else source
        ax.text(0.5, 0.5, f"ore in the mill: {why}", ha="center", va="center",
                transform=ax.transAxes)
        ax.set_title("(b) ore in the mill", fontsize=10)
        return
    shots = ore_in_mill(h5, index)
    colors = plt.cm.viridis(np.linspace(0, 0.9, max(len(shots), 1)))
    for (time, d, m), color in zip(shots, colors):
        if len(d):
            dd, c = cumulative(1e3 * d, m)
            ax.plot(dd, c, drawstyle="steps-post", color=color,
                    label=f"t = {time:.2f} s: {len(d)} particles, {np.sum(m):.4g} kg")
    mark_aperture(ax, aperture)
    log_diameter_axis(ax)
    ax.set_ylabel("cumulative mass passing [%]")
    ax.set_ylim(0, 102)
    ax.set_title(f"(b) ore ('{name}', material {index}) in the mill, from snapshots.h5",
                 fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, which="both", alpha=0.3)


def shade_window(ax, f):
    ax.axvspan(f["window_start_s"], f["window_end_s"], color="tab:orange", alpha=0.12,
               label="steady-state window")


def plot_counts(ax, series, f):
    """(c) counts against time."""
    t = series["time"]
    for col, label in [("breakages", "breakages"), ("fragments", "fragments born"),
                       ("fed_count", "fed"), ("discharged_count", "discharged")]:
        if col in series:
            ax.plot(t, series[col], label=label)
    shade_window(ax, f)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("count since the start")
    ax.set_title("(c) counts", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)


def plot_masses(ax, series, f, err):
    """(d) masses against time, hold-up half-window means, mass-balance error on the right."""
    t = series["time"]
    ax.plot(t, series["ore_mass"], color="tab:green", label="ore in the mill")
    ax.plot(t, series["fed_mass"], color="tab:blue", label="fed")
    ax.plot(t, series["discharged_mass"], color="tab:red", label="discharged (fines included)")
    t0, t1 = f["window_start_s"], f["window_end_s"]
    mid = 0.5 * (t0 + t1)
    ax.plot([t0, mid], [f["window_holdup_first_half_kg"]] * 2, color="k", linewidth=2)
    ax.plot([mid, t1], [f["window_holdup_second_half_kg"]] * 2, color="k", linewidth=2,
            label=f"hold-up, half-window means ({100 * f['window_holdup_change']:+.2g} %)")
    shade_window(ax, f)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("mass [kg]")
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, alpha=0.3)
    right = ax.twinx()
    right.plot(t, err, color="0.5", linewidth=0.7)
    right.set_ylabel("mass-balance error [kg]", color="0.4")
    ax.set_title(f"(d) masses; mass-balance error (grey) at most "
                 f"{f['mass_balance_error_relative']:.2g} of the mill mass", fontsize=10)


def plot_rates(ax, series, f):
    """(e) feed and discharge rates in bins of time, the window's means."""
    t = series["time"]
    span = t[-1] - t[0]
    bins = max(int(round(span / max((f["window_end_s"] - f["window_start_s"]) / 4, 1e-9))), 4)
    edges = np.linspace(t[0], t[-1], min(bins, 80) + 1)
    for col, label, color, key in [("fed_mass", "feed", "tab:blue", "window_feed_rate_kg_s"),
                                   ("discharged_mass", "discharge", "tab:red",
                                    "window_discharge_rate_kg_s")]:
        m = np.interp(edges, t, series[col])
        ax.stairs(np.diff(m) / np.diff(edges), edges, color=color, baseline=None,
                  label=f"{label} rate")
        ax.plot([f["window_start_s"], f["window_end_s"]], [f[key]] * 2, color=color,
                linewidth=2.5, linestyle="--", label=f"{label}, window mean {f[key]:.3g} kg/s")
    shade_window(ax, f)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("rate [kg/s]")
    ax.set_title(f"(e) feed and discharge rates ({len(edges) - 1} bins)", fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, alpha=0.3)


def plot_figures(ax, f):
    """(f) the steady-state figures as text, the slice note beside the kWh/t figures."""
    ax.axis("off")
    lines = [
        f"Steady-state window t = {f['window_start_s']:.3g} .. {f['window_end_s']:.3g} s",
        f"feed rate        {f['window_feed_rate_kg_s']:.4g} kg/s",
        f"discharge rate   {f['window_discharge_rate_kg_s']:.4g} kg/s (particles and fines), "
        f"{ratio(f)} of the feed",
        f"ore hold-up      {f['window_holdup_mean_kg']:.4g} kg, change "
        f"{100 * f['window_holdup_change']:+.3g} % (2nd half vs 1st)",
        f"drive power      {f['window_power_W'] / 1e3:.4g} kW (drum work / window)",
        f"specific energy  {f['window_specific_energy_kwh_per_t']:.4g} kWh/t of product "
        f"(window); whole run {f['run_specific_energy_kwh_per_t']:.4g} kWh/t (run.json)",
    ]
    lines += textwrap.wrap(f"   kWh/t: {f['specific_energy_note']}", 78,
                           subsequent_indent="   ")
    lines += [
        "",
        f"Whole run to t = {f['run_time_s']:.3g} s",
        f"breakages        {f['breakages']}",
        f"product          {f['product_mass_kg']:.4g} kg ({f['product_particles']} particles "
        f"{f['product_particles_kg']:.4g} kg + fines {f['product_fines_kg']:.4g} kg)",
        f"F80 {1e3 * f['f80_m']:.4g} mm ({f['feed']}), P80 {1e3 * f['p80_m']:.4g} mm, "
        f"reduction ratio {f['reduction_ratio']:.3g}",
    ]
    ax.text(0.0, 1.0, "\n".join(lines), transform=ax.transAxes, va="top", ha="left",
            family="monospace", fontsize=7.5)
    ax.set_title("(f) steady-state figures", fontsize=10)


def plot(outdir, figures, data, out):
    run, series = data["run"], data["series"]
    aperture = number(millplot.deck_of(run).get("sieve", {}).get("aperture"))
    aperture = aperture if math.isfinite(aperture) and aperture > 0 else None
    fig, ax = plt.subplots(3, 2, figsize=(13, 13))
    plot_sizes(ax[0, 0], figures, data, aperture)
    plot_ore_in_mill(ax[0, 1], outdir, run, aperture)
    plot_counts(ax[1, 0], series, figures)
    plot_masses(ax[1, 1], series, figures, data["balance_error"])
    plot_rates(ax[2, 0], series, figures)
    plot_figures(ax[2, 1], figures)
    title = millplot.run_title(run, f"ore scene in {os.path.basename(outdir)}")
    fig.suptitle("\n".join(textwrap.wrap(title, 130)), fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)


def json_ready(value):
    """nan and inf as null: JSON has no such numbers."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 epilog="The figures' definitions are in the script's docstring.")
    ap.add_argument("outdir", help="the output folder of an ore run")
    ap.add_argument("-o", "--output", help="PNG to write (default: OUTDIR/grinding.png)")
    ap.add_argument("--window", type=float, metavar="S",
                    help="steady-state window: the last S seconds (default: the last third)")
    ap.add_argument("--json", metavar="FILE", help="also write the printed figures as JSON")
    a = ap.parse_args(argv)
    if a.window is not None and not a.window > 0:
        ap.error("--window must be positive")
    try:
        figures, data = summary(a.outdir, a.window)
    except (OSError, ValueError) as e:
        print(f"plot_grinding.py: {e}", file=sys.stderr)
        return 1
    for warning in consistency_warnings(figures, data):
        print(f"plot_grinding.py: warning: {warning}", file=sys.stderr)
    out = a.output or os.path.join(a.outdir, "grinding.png")
    plot(a.outdir, figures, data, out)
    for line in summary_lines(figures):
        print(line)
    print(f"wrote {out}")
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump({k: json_ready(v) for k, v in figures.items()}, f, indent=1)
            f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
