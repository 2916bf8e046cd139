#!/usr/bin/env python3
"""PrusaSlicer's layers of our 3MF against our plan.

Every layer PrusaSlicer prints (`;Z:`) must be one of our layer tops, in order. A layer of ours it
leaves out (one it sliced to nothing: it writes no `;Z:` for a layer without extrusions) is accepted
only with two independent reasons:
- PrusaSlicer's word: its log's "Empty layer between A and B" (A < z_top < B; run it with
  support_material_contact_distance 0, or it allows a gap of that much without a word), or a layer
  past the three ranges it lists ("(Some lines not shown)"), or above its last printed layer (it
  drops empty top layers silently);
- the mesh: open there wider than PrusaSlicer closes, or a closed section under 1 mm². PrusaSlicer
  slices a layer at its middle and joins open section chains whose ends are within 2 mm
  (TriangleMeshSlicer's make_loops, a fixed max_gap); a chain with an end farther than that from
  every other end is dropped, and a layer whose contours are all dropped has nothing to print. The
  chain ends are where the plane crosses the mesh's boundary edges (edges of one triangle),
  computed here from the 3MF's own vertices and triangles.
And every range PrusaSlicer reports empty must hold a layer of ours it left out.

Usage: peer_3mf_layers.py PLAN.json MODEL.3mf PRUSA.gcode PRUSA.log
"""
import json
import math
import re
import sys
import xml.etree.ElementTree as ET
import zipfile
from collections import Counter

PRUSA_MAX_GAP = 2.0  # mm, PrusaSlicer 2.4+ make_loops
TINY_SECTION = 1.0  # mm²: a closed section this small may give no extrusion (a few line widths square)
Z_TOLERANCE = 1e-3  # mm: PrusaSlicer writes ;Z: rounded to 3 decimals or more


def read_mesh(path):
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("3D/3dmodel.model"))
    ns = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}
    verts = [(float(v.get("x")), float(v.get("y")), float(v.get("z"))) for v in root.iterfind(".//m:vertex", ns)]
    tris = [(int(t.get("v1")), int(t.get("v2")), int(t.get("v3"))) for t in root.iterfind(".//m:triangle", ns)]
    return verts, tris


def boundary_edges(tris):
    uses = Counter()
    for a, b, c in tris:
        for e in ((a, b), (b, c), (c, a)):
            uses[(min(e), max(e))] += 1
    return [e for e, n in uses.items() if n == 1]


def crossing(verts, a, b, z):
    """Where edge a-b crosses the plane at z (x, y), or None; a vertex on the plane counts as above it."""
    (xa, ya, za), (xb, yb, zb) = verts[a], verts[b]
    if (za >= z) == (zb >= z):
        return None
    t = (z - za) / (zb - za)
    return (xa + t * (xb - xa), ya + t * (yb - ya))


def widest_open_end(verts, edges, z):
    """The largest distance from a boundary crossing at z to its nearest other crossing (0: none)."""
    pts = [p for p in (crossing(verts, a, b, z) for a, b in edges) if p]
    widest = 0.0
    for i, p in enumerate(pts):
        nearest = min((math.dist(p, q) for j, q in enumerate(pts) if j != i), default=math.inf)
        widest = max(widest, nearest)
    return widest


def section_area(verts, tris, z):
    """The area of the mesh's section at z, from each crossing triangle's segment oriented by its
    normal (outer rings counter-clockwise): ½ Σ p × q, no chaining needed for a closed mesh."""
    twice = 0.0
    for tri in tris:
        sides = ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0]))
        pts = [p for p in (crossing(verts, a, b, z) for a, b in sides) if p]
        if len(pts) != 2:
            continue
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = (verts[i] for i in tri)
        nx = (by - ay) * (cz - az) - (bz - az) * (cy - ay)
        ny = (bz - az) * (cx - ax) - (bx - ax) * (cz - az)
        p, q = pts
        if (q[0] - p[0]) * -ny + (q[1] - p[1]) * nx < 0:  # along z × n
            p, q = q, p
        twice += p[0] * q[1] - q[0] * p[1]
    return 0.5 * twice


def main():
    plan_path, model_path, gcode_path, log_path = sys.argv[1:5]
    layers = json.load(open(plan_path))["layers"]
    theirs = [float(line[3:]) for line in open(gcode_path) if line.startswith(";Z:")]
    log = open(log_path).read()
    truncated = "(Some lines not shown)" in log  # PrusaSlicer lists three ranges at most
    empty = [(float(a), float(b)) for a, b in re.findall(r"Empty layer between ([0-9.]*[0-9]) and ([0-9.]*[0-9])", log)]
    verts, tris = read_mesh(model_path)
    edges = boundary_edges(tris)

    failures, dropped, max_dz, i, matched = [], [], 0.0, 0, 0
    for z in theirs:  # each printed layer is the next of ours at its height, or a later one
        while i < len(layers) and layers[i]["z_top"] < z - Z_TOLERANCE:
            dropped.append(layers[i])
            i += 1
        if i == len(layers) or abs(layers[i]["z_top"] - z) > Z_TOLERANCE:
            failures.append("PrusaSlicer printed a layer at z %.4f, which is none of ours" % z)
            continue
        max_dz = max(max_dz, abs(layers[i]["z_top"] - z))
        matched += 1
        i += 1
    dropped += layers[i:]

    for layer in dropped:
        top, mid = layer["z_top"], 0.5 * (layer["z_bottom"] + layer["z_top"])
        reported = any(a < top < b + Z_TOLERANCE for a, b in empty)
        unlisted = truncated and top > max(b for _, b in empty)  # past the ranges it lists
        on_top = not theirs or top > theirs[-1] + Z_TOLERANCE  # empty top layers go without a word
        gap, area = widest_open_end(verts, edges, mid), section_area(verts, tris, mid)
        why = "open %.2f mm" % gap if gap > PRUSA_MAX_GAP else "closed, section %.2f mm2" % area
        print("left out: our layer %.2f-%.2f (sliced at %.3f): %s; mesh %s" % (
            layer["z_bottom"], top, mid,
            "reported empty" if reported else "past the ranges listed" if unlisted else
            "above its last layer" if on_top else "NOT reported empty", why))
        if on_top and area >= TINY_SECTION:
            failures.append("our top layer at z %.2f is missing with a %.2f mm2 section" % (top, area))
        elif not (reported or unlisted or on_top):
            failures.append("our layer at z %.2f is missing and PrusaSlicer did not report it empty" % top)
        if gap <= PRUSA_MAX_GAP and area >= TINY_SECTION:
            failures.append("our layer at z %.2f is missing where the mesh is closed, section %.2f mm2" % (top, area))
    for a, b in empty:  # and every range it reports empty is one of ours left out
        if not any(a < l["z_top"] < b + Z_TOLERANCE for l in dropped):
            failures.append("PrusaSlicer reports empty %g-%g, where it printed each of our layers" % (a, b))

    print("PrusaSlicer prints %d layers: %d of our %d at our heights (max |dz| %.2g mm); %d left out" % (
        len(theirs), matched, len(layers), max_dz, len(dropped)))
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
