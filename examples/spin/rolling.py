#!/usr/bin/env python3
"""Checks the rolling of the built-in `spin` scene's balls from a `--dump-state` folder, with no
texflow code: the .npy files are parsed here (the format is a magic string, a header dict and
little-endian float32 rows), the planes and the ball radius are read from the scene file.

Colliders see a ball's centre (docs/collisions.md, spinning spheres): a ball touches a plane
with its centre on it, and the contact point is r below the centre along the plane's unit
normal n. Rolling without slipping means the contact point is still: v + omega x (-r n) = 0, so
|omega x (r n)| / |v| = 1 and, about the contact point, the angular momentum of the rolling ball
is L = I omega + m (r n) x v with I = 2/5 m r^2, i.e. (7/5) m r |v| for pure rolling. A ball is
counted as on a plane when its centre is within r / 10 of it and it moves along it faster than
0.05 m/s.

    texflow render spin --frames 240 --out frames --dump-state dumps --dump-every 20
    python3 examples/spin/rolling.py examples/scenes/spin.toml dumps

Prints, over every dump and every ball in contact, the median and the spread of
|omega x r n| / |v|, the same for L / ((7/5) m r |v|) (m = 1), and the share within 5 % of 1.
Exits 1 if the median is not within 5 % of 1.
"""

import ast
import math
import os
import struct
import sys
import tomllib


def read_npy(path):
    """(shape, flat list of floats) of a little-endian float32 .npy file."""
    with open(path, "rb") as f:
        b = f.read()
    if b[:6] != b"\x93NUMPY":
        raise ValueError(f"{path}: not an .npy file")
    if b[6] == 1:
        (n,) = struct.unpack("<H", b[8:10])
        start = 10
    else:
        (n,) = struct.unpack("<I", b[8:12])
        start = 12
    header = ast.literal_eval(b[start:start + n].decode("latin1"))
    if header["descr"] != "<f4" or header["fortran_order"]:
        raise ValueError(f"{path}: not C-ordered little-endian float32: {header}")
    count = math.prod(header["shape"])
    data = struct.unpack(f"<{count}f", b[start + n:start + n + 4 * count])
    return header["shape"], data


def rows(path):
    shape, v = read_npy(path)
    return [v[4 * i:4 * i + 4] for i in range(shape[0])]


def sub(a, b):
    return [a[k] - b[k] for k in range(3)]


def dot(a, b):
    return sum(a[k] * b[k] for k in range(3))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return math.sqrt(dot(a, a))


def main():
    scene_path, dumps = sys.argv[1], sys.argv[2]
    with open(scene_path, "rb") as f:
        scene = tomllib.load(f)
    r = scene["collisions"]["radius"]
    planes = []
    for p in scene["colliders"]["plane"]:
        n = p["normal"]
        length = norm(n)
        planes.append((p["point"], [c / length for c in n]))
    ratios, momenta = [], []
    frames = sorted(n[len("spins_"):-4] for n in os.listdir(dumps) if n.startswith("spins_"))
    if not frames:
        sys.exit(f"no spins_NNNNN.npy in {dumps}: is it a dump of a scene with collisions.spin?")
    for frame in frames:
        xs = rows(os.path.join(dumps, f"positions_{frame}.npy"))
        vs = rows(os.path.join(dumps, f"velocities_{frame}.npy"))
        ws = rows(os.path.join(dumps, f"spins_{frame}.npy"))
        for x, v, w in zip(xs, vs, ws):
            for point, n in planes:
                gap = dot(sub(x, point), n)
                vt = sub(v, [dot(v, n) * c for c in n])
                speed = norm(vt)
                if abs(gap) > 0.1 * r or speed < 0.05:
                    continue
                omega = w[:3]
                ratios.append(norm(cross(omega, [r * c for c in n])) / speed)
                # About the contact point, m = 1: I omega + (r n) x v.
                spin = [0.4 * r * r * c for c in omega]
                orbital = cross([r * c for c in n], v)
                momenta.append(norm([spin[k] + orbital[k] for k in range(3)]) / (1.4 * r * speed))
    if not ratios:
        sys.exit("no ball was rolling on a plane in these dumps")
    for name, values in [("|omega x r n| / |v|", ratios), ("L / (7/5 m r |v|)", momenta)]:
        values = sorted(values)
        median = values[len(values) // 2]
        near = sum(abs(x - 1.0) <= 0.05 for x in values) / len(values)
        print(
            f"{name}: median {median:.4f}, range [{values[0]:.4f}, {values[-1]:.4f}], "
            f"{100 * near:.0f} % within 5 % of 1 ({len(values)} ball-frames in contact)"
        )
    sys.exit(0 if abs(sorted(ratios)[len(ratios) // 2] - 1.0) <= 0.05 else 1)


if __name__ == "__main__":
    main()
