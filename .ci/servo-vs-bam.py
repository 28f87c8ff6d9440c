#!/usr/bin/env python3
"""armscope testbench against BAM's own simulator on the shared XL330 logs (../shared/reference/servo):
per log and parameter file (BAM's published m1, m3, m6), the MAE within 10 % (or 2 mrad) of BAM's
(BAM_MAE.md) and the simulated trajectory within 5 mrad (mean) of BAM's rollout (bam_sim/); the raw
logs resampled here give the same MAEs as BAM's processed ones. Standard library only."""
import csv, json, os, subprocess, sys, tempfile, time

armscope = os.path.abspath(sys.argv[1])
shared = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "shared", "reference", "servo"))
logs = sorted(f for f in os.listdir(os.path.join(shared, "logs")) if f.endswith(".processed.json"))

# BAM's MAE table, mrad by log and file
bam = {}
for line in open(os.path.join(shared, "BAM_MAE.md")):
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if len(cells) == 10 and cells[0].startswith("xl330_"):
        bam[cells[0]] = dict(zip(["m1", "m2", "m3", "m4", "m5", "m6"], map(float, cells[1:7])))

def column(path, name):
    with open(path) as f:
        return [float(row[name]) for row in csv.DictReader(f)]

failures = []
# BAM's best file on these logs: the older m6, fitted on all 16 (the table's last column)
best_column = [float(line.strip().strip("|").split("|")[9]) for line in open(os.path.join(shared, "BAM_MAE.md")) if line.startswith("| xl330_")]
bam_best = round(sum(best_column) / len(best_column), 2)
with tempfile.TemporaryDirectory() as tmp:
    for model in ["m1", "m3", "m6"]:
        params = os.path.join(shared, "params", "xl330", f"{model}.json")
        summary, traces = os.path.join(tmp, f"{model}.json"), os.path.join(tmp, model)
        subprocess.run([armscope, "testbench", *[os.path.join(shared, "logs", l) for l in logs], "--servo-params", params,
                        "--summary-json", summary, "--trace-dir", traces, "--no-rrd", "--no-mcap", "--quiet"], check=True)
        for entry in json.load(open(summary))["logs"]:
            name, ours = entry["name"], 1e3 * entry["mae_rad"]
            theirs = bam[name][model]
            sim = column(os.path.join(traces, f"{name}.csv"), "position_sim")
            reference = column(os.path.join(shared, "bam_sim", f"{name}_{model}.csv"), "position_sim")
            gap = 1e3 * sum(abs(a - b) for a, b in zip(sim, reference)) / len(reference)
            ok = abs(ours - theirs) <= max(0.1 * theirs, 2.0) and gap <= 5.0 and len(sim) == len(reference)
            print(f"{'ok  ' if ok else 'FAIL'} {model} {name:30s} MAE {ours:8.3f} mrad (BAM {theirs:8.2f}), trajectory {gap:.2e} mrad from BAM's")
            if not ok:
                failures.append(f"{model} {name}")
    # raw logs, resampled by armscope as bam.process does: the same MAEs as the processed logs
    raw = [os.path.join(shared, "logs", l.replace(".processed.", ".raw.")) for l in logs]
    summary = os.path.join(tmp, "raw.json")
    subprocess.run([armscope, "testbench", *raw, "--servo-params", os.path.join(shared, "params", "xl330", "m6.json"),
                    "--summary-json", summary, "--no-rrd", "--no-mcap", "--quiet"], check=True)
    processed = {e["name"]: e["mae_rad"] for e in json.load(open(os.path.join(tmp, "m6.json")))["logs"]}
    for entry in json.load(open(summary))["logs"]:
        same = abs(entry["mae_rad"] - processed[entry["name"]]) <= 1e-9
        print(f"{'ok  ' if same else 'FAIL'} raw {entry['name']:30s} resampled here: MAE {1e3 * entry['mae_rad']:.6f} mrad, processed {1e3 * processed[entry['name']]:.6f}")
        if not same:
            failures.append(f"raw {entry['name']}")
    # identify on the 8 logs (with armscope's motor voltage limit): the fit must explain them better
    # than BAM's best file for them (m6 of 16837b3, fitted on all 16 logs: 28.98 mrad on these 8),
    # within the bar's 60 s
    out, summary = os.path.join(tmp, "fit.json"), os.path.join(tmp, "fit-summary.json")
    started = time.monotonic()
    subprocess.run([armscope, "identify", *[os.path.join(shared, "logs", l) for l in logs], "--actuator", "xl330", "--friction-model", "m6",
                    "--fit-motor-voltage-limit", "--out", out, "--summary-json", summary, "--quiet"], check=True)
    seconds = time.monotonic() - started
    fitted = 1e3 * json.load(open(summary))["train_mean_mae_rad"]
    ok = fitted <= bam_best and seconds < 60.0
    print(f"{'ok  ' if ok else 'FAIL'} identify on {len(logs)} logs: {fitted:.2f} mrad (BAM's best file {bam_best} mrad) in {seconds:.1f} s")
    if not ok:
        failures.append("identify")
if failures:
    sys.exit(f"servo-vs-bam: {len(failures)} failed: {', '.join(failures)}")
print(f"servo-vs-bam: {3 * len(logs)} replays as BAM's simulator, {len(logs)} raw logs resampled as bam.process")
