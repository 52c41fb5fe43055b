#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Write docs/performance.md from a Google Benchmark JSON file and peak-memory runs of
the command-line tool; plot time against points (log-log) with gnuplot."""

import argparse
import json
import os
import re
import subprocess
import sys

PAPER = [  # Table I of the paper (Pentium IV 3.4 GHz): points, stages, total [s]
    ("Door", 46255, 0.519, 0.204, 0.307, 3.971, 5.001),
    ("Chair", 1544, 0.013, 0.006, 0.008, 0.025, 0.052),
    ("Cube", 5432, 0.055, 0.027, 0.022, 0.050, 0.154),
]


def load(path):
    with open(path) as f:
        data = json.load(f)
    runs = {}
    for b in data["benchmarks"]:
        name = b["name"]
        if b.get("aggregate_name") not in (None, "median"):
            continue
        key = re.sub(r"/repeats:\d+|/iterations:\d+|/min_time:[\d.]+|/real_time|_median",
                     "", name)
        runs[key] = b
    return data.get("context", {}), runs


def seconds(b):
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
    return b["real_time"] * scale


def peak_memory(tool, scan):
    """Peak resident memory [bytes] of one run of the tool writing the labeled cloud
    beside the scan (its own rusage)."""
    labels = os.path.splitext(scan)[0] + "_labels.pcd"
    pid = os.spawnv(os.P_NOWAIT, tool, [tool, scan, "-o", labels])
    _, status, usage = os.wait4(pid, 0)
    if status != 0:
        sys.exit(f"{tool} {scan} failed")
    return usage.ru_maxrss * 1024


def door_rows(runs):
    rows = []
    for key, b in sorted(runs.items(), key=lambda kv: kv[1].get("points", 0)):
        m = re.match(r"BM_Pipeline_Door/(\d+)$", key)
        if not m:
            continue
        rg = runs.get(f"BM_RegionGrowing_Door/{m.group(1)}")
        rows.append((int(b["points"]), b, rg))
    return rows


def frame_loop_lines(runs, rows):
    """The table of frames segmented one after another (BM_FrameLoop_Door) beside the
    door table's runs (a new segmenter each, repetitions among the other sizes')."""
    # A run's name is BM_Pipeline_Door/<size asked for>/...: the same size's loop.
    loop = {n: runs.get(f"BM_FrameLoop_Door/{b['name'].split('/')[1]}")
            for n, b, _ in rows}
    if not any(loop.values()):
        return []
    out = ["", "## Frames one after another", "",
           "`BM_FrameLoop_Door`: one segmenter segments the same scan again and again "
           "after a first frame that is not timed, as a program that segments a "
           "sensor's frames holds it (median of 3 repetitions of at least 4 s of "
           "frames each); beside it the table above's runs, whose repetitions fall "
           "among the other sizes' and the peer's and find memory that those freed. "
           "Page faults per frame from `getrusage` (the memory the process mapped "
           "afresh; each costs microseconds on a virtual machine).", "",
           "| points | new segmenter, among other sizes (s) | page faults per frame | "
           "frame loop (s) | page faults per frame |", "|---|---|---|---|---|"]
    for n, b, _ in rows:
        f = loop.get(n)
        if f:
            out.append(f"| {n:,} | {seconds(b):.4f} | {b.get('faults', 0):,.0f} | "
                       f"{seconds(f):.4f} | {f.get('faults', 0):,.0f} |")
    big = [(n, b, loop.get(n)) for n, b, _ in rows if n >= 900000]
    if len(big) == 2 and big[0][2] and big[1][2]:
        out += ["", f"3M / 1M: {seconds(big[1][1]) / seconds(big[0][1]):.2f} with a new "
                f"segmenter among the other sizes, "
                f"{seconds(big[1][2]) / seconds(big[0][2]):.2f} in the frame loop."]
    return out


def write_plot(rows, plot):
    dat = plot + ".dat"
    with open(dat, "w") as f:
        for n, b, rg in rows:
            f.write(f"{n} {seconds(b)} {seconds(rg) if rg else 'NaN'}\n")
    script = f"""set terminal pngcairo size 900,600
set output '{plot}'
set logscale xy
set grid
set xlabel 'points'
set ylabel 'time [s]'
set key left top
set termoption noenhanced
set title 'Segmentation time against cloud size (simulated door scans, this machine)'
plot '{dat}' using 1:2 with linespoints lw 2 title 'pcl_selective_seg (whole pipeline)', \\
     '{dat}' using 1:3 with linespoints lw 2 title 'NormalEstimation + RegionGrowing', \\
     '{dat}' using 1:($1*{seconds(rows[-1][1]) / rows[-1][0]}) with lines dt 2 title 'linear'
"""
    subprocess.run(["gnuplot"], input=script.encode(), check=True)
    os.remove(dat)


def load_note(load):
    """A sentence on the machine's load around the benchmark run."""
    if not load:
        return ""
    # The suite's own two threads raise the load after it to about 1; only the load
    # before it tells whether other work was running.
    busy = float(load[0].split()[0]) > 0.7
    return (f" Load average (1, 5, 15 min) {load[0]} before the suite, {load[1]} after"
            " it (the suite's own threads included)"
            + (": other work was running on the cores when the suite began, so the"
               " timings (both columns) may be pessimistic." if busy else "."))


def probe_note(paths):
    """A sentence on the spell probe: the 46k pipeline on one thread and on two, before
    and after the suite (JSON files of the benchmark, in that order)."""
    if not paths:
        return ""
    ms = []
    for path in paths:
        _, runs = load(path)
        b = runs.get("BM_Pipeline_Door/46255")
        if not b:
            return ""
        ms.append(seconds(b) * 1e3)
    parts = [f"{when} {one:.1f} / {two:.1f} ms ({one / two:.2f}x)"
             for when, one, two in (("before the suite", ms[0], ms[1]),
                                    ("after it", ms[2], ms[3]))]
    return (" Spell probe (the 46k door scan alone, median of 3, on one thread / on two): "
            + ", ".join(parts) + ". Two threads gain about 1.6x when each vCPU gets a"
            " core's throughput; near 1x the two shared one core (a slow spell), and the"
            " parallel stages ran about as fast as on one thread.")


def cpu_model():
    """The processor's model name from /proc/cpuinfo (Linux), or '?'."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "?"


def markdown(context, runs, rows, memory, load=None, probe=None):
    out = ["# Performance", "",
           "Generated by `apps/run_benchmarks.sh build ../shared/data` (Google Benchmark "
           "suite `test/benchmark/benchmark_pipeline.cpp`, then this report). Release "
           "build, this 2-core machine, real time; the pipeline and the peer are each "
           "the median of 3 repetitions (the peer's of one iteration each); the "
           "repetitions of all sizes and of both run in a random interleaved order, so "
           "that a slow spell of the machine does not fall on all three repetitions of "
           "one of them. Timings are never asserted in tests.", "",
           f"Machine: {context.get('num_cpus', '?')} CPUs ({cpu_model()}) at "
           f"{context.get('mhz_per_cpu', '?')} MHz, date {context.get('date', '?')}, "
           f"OpenMP wait policy {os.environ.get('OMP_WAIT_POLICY') or 'default'}, "
           f"glibc tunables {os.environ.get('GLIBC_TUNABLES') or 'none'}."
           + load_note(load) + probe_note(probe), "",
           "## Whole pipeline by size and stage (simulated door scans, Fig. 6)", "",
           "| points | Delaunay (s) | Normal Calc. (s) | Octree Gen. (s) | Merge Voxels (s) "
           "| Total (s) | NormalEstimation + RegionGrowing (s) | speed-up |",
           "|---|---|---|---|---|---|---|---|"]
    for n, b, rg in rows:
        total = seconds(b)
        ratio = f"{seconds(rg) / total:.2f}x" if rg else "-"
        out.append(f"| {n:,} | {b['delaunay_s']:.4f} | {b['normals_s']:.4f} | "
                   f"{b['octree_s']:.4f} | {b['merge_s']:.4f} | {total:.4f} | "
                   f"{seconds(rg):.3f} | {ratio} |" if rg else "")
    out += frame_loop_lines(runs, rows)
    out += ["", "The paper's Table I (Pentium IV 3.4 GHz, 2008):", "",
            "| data set | points | Delaunay (s) | Normal Calc. (s) | Octree Gen. (s) | "
            "Merge Voxels (s) | Total (s) |", "|---|---|---|---|---|---|---|"]
    out += [f"| {r[0]} | {r[1]:,} | {r[2]} | {r[3]} | {r[4]} | {r[5]} | {r[6]} |"
            for r in PAPER]
    out += ["", "## Real frames", "",
            "| frame | points | Delaunay (s) | Normal Calc. (s) | Octree Gen. (s) | "
            "Merge Voxels (s) | Total (s) | NormalEstimation + RegionGrowing (s) | "
            "speed-up |", "|---|---|---|---|---|---|---|---|---|"]
    for frame, label in (("Mosd", "mOSD test0"), ("Mug", "stereo mug scene")):
        b, rg = runs.get(f"BM_Pipeline_{frame}"), runs.get(f"BM_RegionGrowing_{frame}")
        if b and "points" in b:
            out.append(f"| {label} | {int(b['points']):,} | {b['delaunay_s']:.4f} | "
                       f"{b['normals_s']:.4f} | {b['octree_s']:.4f} | "
                       f"{b['merge_s']:.4f} | {seconds(b):.4f} | {seconds(rg):.3f} | "
                       f"{seconds(rg) / seconds(b):.2f}x |")
    out += ["", "## Peak memory of the command-line tool", "",
            "`pcl_selective_seg SCAN.pcd -o LABELS.pcd` (load, segment, write the "
            "labeled cloud), peak resident memory of the process:", "", "| points | peak (MB) | bytes per point |",
            "|---|---|---|"]
    for n, peak in memory:
        out.append(f"| {n:,} | {peak / 1e6:.0f} | {peak / n:.0f} |")
    out += ["", "![time against points](images/performance_scaling.png)", ""]
    return "\n".join(line for line in out if line is not None)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--benchmark", required=True)
    p.add_argument("--tool", required=True)
    p.add_argument("--scans", required=True)
    p.add_argument("--markdown", required=True)
    p.add_argument("--plot", required=True)
    p.add_argument("--load", nargs=2, metavar=("BEFORE", "AFTER"),
                   help="load averages (/proc/loadavg) around the benchmark run")
    p.add_argument("--probe", nargs=4, metavar="JSON",
                   help="spell probe: the 46k benchmark on 1 and 2 threads before the "
                        "suite, then on 1 and 2 after it")
    a = p.parse_args()
    context, runs = load(a.benchmark)
    rows = door_rows(runs)
    memory = []
    for name in sorted(os.listdir(a.scans)):
        m = re.match(r"door_(\d+)\.pcd$", name)
        if m:
            memory.append((int(m.group(1)), peak_memory(a.tool, os.path.join(a.scans, name))))
    memory.sort()
    write_plot(rows, a.plot)
    text = markdown(context, runs, rows, memory, a.load, a.probe)
    notes = os.path.join(os.path.dirname(a.markdown), "performance_notes.md")
    if os.path.exists(notes):  # the hand-written analysis, kept across runs
        with open(notes) as f:
            text += "\n" + f.read()
    with open(a.markdown + ".tmp", "w") as f:
        f.write(text)
    os.replace(a.markdown + ".tmp", a.markdown)


if __name__ == "__main__":
    main()
