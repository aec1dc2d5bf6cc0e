"""How far `adse world --follow-ideal`'s ground-truth controller strays from
the ideal path outside junctions (issue 17's 1 m bound).

  ideal_path_error.py <net.net.xml> <world-check folder>

Prints the largest distance (m) of a trajectory sample from the ideal path
among the samples outside every junction's shape of the net, the largest
over all samples, and the number of places where the ideal path turns
tighter than the car can (U-turns, hairpin corners): its heading changes
faster than 1 / (the ego's minimum turning radius, 2.7 m wheelbase at
0.6 rad steering: 3.9 m) over 4 m of path. There the car must leave the
path, and does so beyond the junction's shape. A three-point turn's cusps
(where the ideal path reverses, at a gear change) are no such place: the
path is cut there and each piece counted alone. Coordinates are SUMO net
coordinates, as adse's world uses them.
"""
import csv
import sys

import numpy as np
import sumolib


def read_xy(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(r["x_m"]), float(r["y_m"])] for r in rows])


def distances_to_polyline(points, line):
    a, b = line[:-1], line[1:]
    ab = b - a
    len2 = np.maximum((ab * ab).sum(axis=1), 1e-12)
    out = np.empty(len(points))
    for i, p in enumerate(points):
        t = np.clip(((p - a) * ab).sum(axis=1) / len2, 0.0, 1.0)
        closest = a + t[:, None] * ab
        out[i] = np.sqrt(((closest - p) ** 2).sum(axis=1)).min()
    return out


def inside(polygon, p):
    # Even-odd rule, as geometry::InsidePolygon.
    x, y = p
    result = False
    j = len(polygon) - 1
    for i in range(len(polygon)):
        (xi, yi), (xj, yj) = polygon[i], polygon[j]
        if (yi > y) != (yj > y) and x < (xj - xi) * (y - yi) / (yj - yi) + xi:
            result = not result
        j = i
    return result


MIN_TURN_RADIUS_M = 2.7 / np.tan(0.6)


def pieces_between_cusps(line):
    # A cusp: the path goes back the way it came (over 150 degrees at one
    # vertex), as a manoeuvre does at a gear change. Pieces share it.
    moved = np.concatenate([[True], np.linalg.norm(np.diff(line, axis=0),
                                                   axis=1) > 1e-9])
    line = line[moved]
    u = np.diff(line, axis=0)
    u /= np.linalg.norm(u, axis=1)[:, None]
    cusps = list(np.nonzero((u[:-1] * u[1:]).sum(axis=1) < -0.866)[0] + 1)
    bounds = [0] + cusps + [len(line) - 1]
    return [line[a:b + 1] for a, b in zip(bounds[:-1], bounds[1:])]


def tight_turns(line, window_m=4.0):
    if len(line) < 3:
        return 0
    step = np.linalg.norm(np.diff(line, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(step)])[:-1]
    heading = np.unwrap(np.arctan2(np.diff(line[:, 1]), np.diff(line[:, 0])))
    count, i = 0, 0
    while i < len(heading):
        j = min(np.searchsorted(s, s[i] + window_m), len(heading) - 1)
        if abs(heading[j] - heading[i]) > window_m / MIN_TURN_RADIUS_M:
            count += 1
            i = np.searchsorted(s, s[i] + 25.0)  # one place, not each step
        else:
            i += 1
    return count


def main():
    net = sumolib.net.readNet(sys.argv[1], withInternal=True)
    folder = sys.argv[2]
    trajectory = read_xy(folder + "/trajectory.csv")
    ideal = read_xy(folder + "/ideal_path.csv")
    error = distances_to_polyline(trajectory, ideal)
    shapes = [np.array(n.getShape()) for n in net.getNodes()
              if len(n.getShape()) >= 3]
    boxes = np.array([[s[:, 0].min(), s[:, 1].min(), s[:, 0].max(),
                       s[:, 1].max()] for s in shapes])
    outside = np.ones(len(trajectory), dtype=bool)
    for i, p in enumerate(trajectory):
        near = np.nonzero((boxes[:, 0] <= p[0]) & (p[0] <= boxes[:, 2]) &
                          (boxes[:, 1] <= p[1]) & (p[1] <= boxes[:, 3]))[0]
        outside[i] = not any(inside(shapes[k], p) for k in near)
    print("%.2f %.2f %d" % (error[outside].max() if outside.any() else 0.0,
                            error.max(),
                            sum(tight_turns(p) for p in pieces_between_cusps(ideal))))


if __name__ == "__main__":
    main()
