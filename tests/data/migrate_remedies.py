#!/usr/bin/python3
"""Adds typed remedies to the bottleneck column of recorded campaign indexes.

Campaign indexes written before typed remedies hold, per bottleneck of
/evaluations/bottlenecks_json, only the readable text ("more cores; lower
sensor rate"). This maps that text back to the typed remedies the diagnosis
produced it from (analysis/diagnosis/remedy.h) and adds them as "remedies":
[{"kind": "more_cores", "target": "<node>"}, ...], as the campaign now writes
them. Only that dataset is rewritten, with the writer's layout
(analysis/runfile/hdf5_util.cc); every other object is left as it is.

    /usr/bin/python3 tests/data/migrate_remedies.py [campaign.h5 ...]

Without arguments it migrates tests/data/robotaxi_exhaustive and
tests/data/reference_study. Rows already migrated are left alone, so running
it twice changes nothing. Needs h5py.
"""

import json
import os
import re
import sys

import h5py
import numpy as np

COLUMN = "evaluations/bottlenecks_json"

# "lower sensor rate" is about the sensor topic the cpu_bound node falls
# behind, which the legacy row does not name: in the bundled stack
# (stack/nodes/ad_stack.cc, unchanged since these recordings) each node with
# that remedy subscribes to exactly one topic from outside the graph.
SENSOR_INPUT = {
    "lidar_driver": "/sensing/lidar/points_raw",
    "distortion_corrector": "/sensing/odometry",  # its "twist" input
    "ekf_localizer": "/sensing/odometry",
}

# The phrases of RemedyText, matched whole.
PUBLISHER = re.compile(r"raise the rate of (.+)'s publisher \((.*)\)")
SENSOR = re.compile(r"raise the rate of sensor (.+)")
TIMER = re.compile(r"shorten the period of (.+)")
RELIEVE = re.compile(r"relieve (.+) \(cpu_bound\)")

# As analysis/runfile/hdf5_util.cc sizes a column's chunks.
MAX_CHUNK_ROWS = 4096
MAX_CHUNK_BYTES = 512 * 1024


def typed_remedies(bottleneck):
    """The typed remedies of one legacy bottleneck, in the text's order."""
    node = bottleneck["node"]
    remedies = []
    for part in bottleneck["remedy"].split("; "):
        if part in ("more cores", "higher frequency"):
            remedies.append({"kind": part.replace(" ", "_"), "target": node})
        elif part == "lower sensor rate":
            if node not in SENSOR_INPUT:
                raise ValueError(f"no known sensor input of {node!r} for "
                                 f"'lower sensor rate'")
            remedies.append({"kind": "lower_sensor_rate",
                             "target": SENSOR_INPUT[node]})
        elif m := PUBLISHER.fullmatch(part):
            remedies.append({"kind": "raise_publisher_rate",
                             "target": m[1], "publisher": m[2]})
        elif m := SENSOR.fullmatch(part):
            remedies.append({"kind": "raise_sensor_rate", "target": m[1]})
        elif m := TIMER.fullmatch(part):
            remedies.append({"kind": "shorten_timer_period", "target": m[1]})
        elif m := RELIEVE.fullmatch(part):
            remedies.append({"kind": "relieve_node", "target": m[1]})
        else:
            raise ValueError(f"unknown remedy text {part!r} of {node!r}")
    return remedies


def dump(value):
    # nlohmann::json::dump(): keys sorted, no spaces, UTF-8 as is. The
    # recorded rows round-trip through this byte for byte.
    return json.dumps(value, separators=(",", ":"), sort_keys=True,
                      ensure_ascii=False)


def migrate(path):
    with h5py.File(path, "r+") as f:
        old = f[COLUMN]
        rows = [s.decode("utf-8") for s in old[:]]
        changed = 0
        new_rows = []
        for i, text in enumerate(rows):
            bottlenecks = json.loads(text)
            if dump(bottlenecks) != text:
                raise ValueError(f"{path}: row {i} is not in the writer's "
                                 f"JSON form")
            for b in bottlenecks:
                if "remedies" not in b:
                    b["remedies"] = typed_remedies(b)
                    changed += 1
            new_rows.append(dump(bottlenecks).encode("utf-8"))
        if changed == 0:
            print(f"{path}: already migrated")
            return
        # The writer's layout: NUL-padded UTF-8 as wide as the longest row,
        # the old creation properties (shuffle, deflate 4, Fletcher-32, no
        # times, unlimited) with the chunk the writer picks for that width.
        width = max(1, max(len(r) for r in new_rows))
        string_type = old.id.get_type().copy()
        string_type.set_size(width)
        dcpl = old.id.get_create_plist()
        chunk_rows = min(max(MAX_CHUNK_BYTES // width, 1), MAX_CHUNK_ROWS)
        if new_rows:
            chunk_rows = min(chunk_rows, len(new_rows))
        dcpl.set_chunk((chunk_rows,))
        if old.attrs:
            raise ValueError(f"{path}: {COLUMN} has attributes")
        group = f[os.path.dirname(COLUMN)]
        name = os.path.basename(COLUMN)
        del group[name]
        space = h5py.h5s.create_simple((len(new_rows),),
                                       (h5py.h5s.UNLIMITED,))
        dataset = h5py.h5d.create(group.id, name.encode(), string_type,
                                  space, dcpl=dcpl)
        data = np.array(new_rows, dtype=f"S{width}")
        dataset.write(h5py.h5s.ALL, h5py.h5s.ALL, data, mtype=string_type)
        dataset.close()
        print(f"{path}: typed remedies added to {changed} bottlenecks "
              f"in {len(rows)} rows")


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    paths = argv[1:] or [
        os.path.join(here, "robotaxi_exhaustive", "campaign.h5"),
        os.path.join(here, "reference_study", "campaign.h5"),
    ]
    for path in paths:
        migrate(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
