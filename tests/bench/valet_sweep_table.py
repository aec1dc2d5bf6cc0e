# The per-point table of the valet sweep in the README ("Automated valet
# parking", "A sweep"), from the campaign of that sweep, which runs each
# case several times (harness.replicas):
#   /usr/bin/python3 tests/bench/valet_sweep_table.py <campaign>/campaign.h5
# Per point and case: the runs that parked cleanly (were feasible), what
# the others did, the median nav time (a run stopped at the bound counts
# as the bound), the median parking error of the runs that reached the
# slot, the smallest clearance; last, the median control rate of the
# runs not stopped early. The bound is read from the campaign's stored
# scenario.
import sys, collections, math, re, statistics
import h5py

f = h5py.File(sys.argv[1], "r")


def nav_time_bound():  # the stored scenario's constraint nav_time_s <= B
    text = f.attrs["scenario_text"]
    text = text.decode() if isinstance(text, bytes) else text
    m = re.search(r"nav_time_s\s*<=?\s*([0-9.eE+-]+)", text)
    if not m:
        sys.exit(f"{sys.argv[1]}: its scenario has no nav_time_s <= <bound> "
                 "constraint, which the table's medians need")
    return float(m.group(1))


BOUND = nav_time_bound()


def table(name):
    g = f[name]
    cols = {}
    for k in g:
        if isinstance(g[k], h5py.Dataset):
            cols[k] = g[k].asstr()[:] if g[k].dtype.kind in "SO" else g[k][:]
    for sub in ("point", "metrics"):
        for n in g[sub].attrs["names"]:
            n = n.decode() if isinstance(n, bytes) else n
            cols[n] = g[sub][n][:]
    return [{k: v[i] for k, v in cols.items()} for i in range(len(cols["index"]))]


def fin(x):
    return x is not None and math.isfinite(float(x))


def stopped(r):  # ended early at the nav-time bound
    return str(r["reason"]).startswith("constraint_violated")


def reached(r):  # stood in the slot when its manoeuvre ended
    return str(r["reason"]) in ("goal_reached", "parked_out_of_tolerance")


def other(r):
    reason = str(r["reason"])
    touching = fin(r.get("obstacle_collisions")) and r["obstacle_collisions"] > 0
    if stopped(r) or reason == "timeout":
        label = f"not parked by {BOUND:g} s"
    elif reason == "no_path":
        label = "no path"
    elif reason == "parked_out_of_tolerance":
        label = "out of tolerance"
    elif reason == "goal_reached" and touching:
        return "touching a parked car"
    else:
        label = reason
    return label + (" and touching" if touching else "")


def joined(labels):
    c = collections.Counter(labels)
    return "; ".join(l if n == 1 else f"{l} ×{n}" for l, n in c.items()) or "—"


ev = {int(r["index"]): r for r in table("evaluations")}
reps = collections.defaultdict(list)
for r in table("replicas"):
    reps[int(r["index"])].append(r)
cases = sorted({int(r["task_case"]) for rs in reps.values() for r in rs})
rows = []
for i, e in ev.items():
    rs = reps[i] or [e]
    line = [f"{e['cores']:g}", f"{e['freq_ghz']:g}",
            ("yes" if e["feasible"] else "no") + (" (unstable)" if e.get("unstable", 0) else "")]
    for c in cases:
        runs = [r for r in rs if int(r["task_case"]) == c]
        clean = [r for r in runs if r["feasible"]]
        line.append(f"{len(clean)} of {len(runs)}")
        line.append(joined([other(r) for r in runs if not r["feasible"]]))
        med = statistics.median(
            BOUND if stopped(r) or not fin(r["nav_time_s"]) else float(r["nav_time_s"])
            for r in runs)
        line.append(f"≥ {BOUND:g}" if med >= BOUND else f"{med:.1f}")
        slot = [r for r in runs if reached(r)]
        errors = [r for r in slot if fin(r["parking_position_error_m"])]
        if errors:
            line.append(f"{statistics.median(r['parking_position_error_m'] for r in errors):.2f} m / "
                        f"{statistics.median(abs(r['parking_yaw_error_deg']) for r in errors):.1f}°")
        else:
            line.append("—")
        cl = [r["min_clearance_m"] for r in slot if fin(r["min_clearance_m"])]
        line.append(f"{max(0.0, min(cl)):.2f}" if cl else "—")
    ctrl = [r["ctrl_rate_hz"] for r in rs if fin(r["ctrl_rate_hz"]) and not stopped(r)]
    line.append(f"{statistics.median(ctrl):.1f}" if ctrl else "—")
    rows.append((e["cores"], e["freq_ghz"], line))
for _, _, line in sorted(rows, key=lambda t: (t[0], t[1])):
    print("| " + " | ".join(line) + " |")
