#!/usr/bin/python3
"""Step 11b, saliency maps: for each model (80 mm), a PNG preview of the spectral map, the share of
the surface above 0.5, the map's stability under remeshing (the placed mesh against the same
surface split 1-to-4: Pearson correlation at the shared vertices) and, for suzanne, the mirror
symmetry. Usage: tests/bench/saliency_maps_bench.py SALIENT OUT_DIR [MODEL:UP ...]
Needs numpy (Debian python3-numpy)."""
import os, subprocess, sys, tempfile
import numpy as np

MODELS = ["stanford-bunny.obj:y", "spot.obj:y", "fandisk.obj:y", "cow.obj:y", "teapot.obj:y",
          "suzanne.obj:y", "igea.ply:z"]


def read_ply(path):  # salient's own PLY: x y z quality r g b, then uchar-counted int triangles
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + 11
    header = data[:end].decode()
    nv = int(header.split("element vertex ")[1].split()[0])
    nf = int(header.split("element face ")[1].split()[0])
    v = np.frombuffer(data[end:end + nv * 19], np.dtype([("p", "<f4", 3), ("q", "<f4"), ("c", "u1", 3)]))
    f = np.frombuffer(data[end + nv * 19:end + nv * 19 + nf * 13], np.dtype([("n", "u1"), ("i", "<i4", 3)]))
    return v["p"].astype(float), v["q"].astype(float), f["i"].astype(np.int64)


def write_subdivided(points, faces, path):  # original vertices first, then one per edge midpoint
    mid, extra, out = {}, [], []
    def m(a, b):
        key = (min(a, b), max(a, b))
        if key not in mid:
            mid[key] = len(points) + len(extra)
            extra.append((points[a] + points[b]) / 2)
        return mid[key]
    for a, b, c in faces.tolist():
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    with open(path, "w") as o:
        o.writelines("v %.7f %.7f %.7f\n" % tuple(p) for p in list(points) + extra)
        o.writelines("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1) for t in out)


def main():
    salient, out = sys.argv[1], sys.argv[2]
    cases = sys.argv[3:] or MODELS
    models = os.path.join(os.path.dirname(__file__), "../../../shared/models")
    os.makedirs(out, exist_ok=True)
    tmp = tempfile.mkdtemp()
    print("| model | area above 0.5 | remeshing stability (corr.) | mirror symmetry |")
    print("|---|---:|---:|---:|")
    for case in cases:
        model, up = case.rsplit(":", 1)
        name = model.rsplit(".", 1)[0]
        placed = os.path.join(tmp, name + ".ply")
        subprocess.run([salient, "saliency", os.path.join(models, model), "--up", up, "--height", "80",
                        "-o", placed, "--png", os.path.join(out, name + ".png")], check=True,
                       stdout=subprocess.DEVNULL)
        p, q, f = read_ply(placed)
        area = np.linalg.norm(np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]), axis=1) / 2
        above = area[q[f].mean(axis=1) > 0.5].sum() / area.sum()
        split = os.path.join(tmp, name + "-split.obj")
        write_subdivided(p, f, split)
        again = os.path.join(tmp, name + "-split.ply")
        subprocess.run([salient, "saliency", split, "--up", "z", "-o", again], check=True, stdout=subprocess.DEVNULL)
        q2 = read_ply(again)[1][:len(q)]
        stable = np.corrcoef(q, q2)[0, 1]
        mirror = ""
        if name == "suzanne":
            x0 = (p[:, 0].min() + p[:, 0].max()) / 2
            mirrored = p * [-1, 1, 1] + [2 * x0, 0, 0]
            d = np.linalg.norm(p[None, :, :] - mirrored[:, None, :], axis=2)
            j = d.argmin(axis=1)
            ok = d[np.arange(len(p)), j] < 1e-3 * np.ptp(p)
            mirror = "%.3f" % np.corrcoef(q[ok], q[j[ok]])[0, 1]
        print(f"| {model} | {above:.3f} | {stable:.3f} | {mirror} |")


if __name__ == "__main__":
    main()
