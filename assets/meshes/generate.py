#!/usr/bin/env python3
"""Writes the obstacle meshes the built-in scenes use (metres, y up, outward-facing
triangles): table.obj, turntable.obj and the arm's frames, arm/arm_0000.obj to
arm/arm_0015.obj. Run from this folder: python3 generate.py"""

import math
import os


def write(name, vertices, triangles, comment):
    with open(name, "w") as out:
        out.write(f"# {comment}\n# Written by assets/meshes/generate.py.\n")
        for v in vertices:
            out.write("v {:.6g} {:.6g} {:.6g}\n".format(*v))
        for t in triangles:
            out.write("f {} {} {}\n".format(*(i + 1 for i in t)))


def cuboid(lo, hi, base):
    """A box from lo to hi: 8 corners, 12 triangles wound outwards."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
         (3, 7, 6), (3, 6, 2), (0, 4, 7), (0, 7, 3), (1, 2, 6), (1, 6, 5)]
    return v, [tuple(i + base for i in t) for t in f]


def table():
    """A 1.2 m x 0.8 m table top, 5 cm thick, 75 cm up, on four 5 cm legs."""
    vertices, triangles = [], []
    parts = [((-0.6, 0.70, -0.4), (0.6, 0.75, 0.4))]
    for sx in (-1, 1):
        for sz in (-1, 1):
            x, z = 0.52 * sx, 0.32 * sz
            parts.append(((x - 0.025, 0.0, z - 0.025), (x + 0.025, 0.70, z + 0.025)))
    for lo, hi in parts:
        v, t = cuboid(lo, hi, len(vertices))
        vertices += v
        triangles += t
    return vertices, triangles


def turntable(radius=0.5, height=0.3, rings=8):
    """A closed cylinder about the y axis, from y = 0 to `height`, with 6 x `rings` sides.
    Each cap is cut into `rings` rings, ring k having 6k corners, so that its triangles are
    all about as wide as they are long."""
    vertices, triangles = [], []

    def ring(y, r, n):
        start = len(vertices)
        for i in range(n):
            a = 2 * math.pi * i / n
            vertices.append((r * math.cos(a), y, r * math.sin(a)))
        return start, n

    def zip_rings(inner, outer, up):
        """Triangles between two rings, walking both by angle."""
        (a0, m), (b0, n) = inner, outer
        i = j = 0
        while i < m or j < n:
            # Advance the ring whose next corner comes first in angle.
            if j < n and (i >= m or (j + 1) / n <= (i + 1) / m):
                t = (a0 + i % m, b0 + (j + 1) % n, b0 + j)
                j += 1
            else:
                t = (a0 + i % m, a0 + (i + 1) % m, b0 + j % n)
                i += 1
            triangles.append(t if up else (t[0], t[2], t[1]))

    def cap(y, up):
        centre = len(vertices)
        vertices.append((0.0, y, 0.0))
        rims = [ring(y, radius * k / rings, 6 * k) for k in range(1, rings + 1)]
        first, n = rims[0]
        for i in range(n):
            t = (centre, first + (i + 1) % n, first + i)
            triangles.append(t if up else (t[0], t[2], t[1]))
        for inner, outer in zip(rims, rims[1:]):
            zip_rings(inner, outer, up)
        return rims[-1]

    bottom, n = cap(0.0, False)
    top, _ = cap(height, True)
    for i in range(n):
        j = (i + 1) % n
        triangles += [(bottom + i, top + i, top + j), (bottom + i, top + j, bottom + j)]
    return vertices, triangles


def arm(angle, segments=12, radius=0.05, length=0.9, height=0.8, elbow_width=0.06):
    """A closed tube along x, `length` long at `height`, its far half (the forearm) bent up
    by `angle` radians about the elbow at x = 0; near the elbow the bend is shared out
    smoothly, so the tube bends there rather than breaking. One frame of the sequence."""
    vertices, triangles = [], []
    step = 0.05
    rings = round(length / step) + 1

    def bend(x, y, z):
        """A point of the straight tube, bent."""
        s = min(max((x + elbow_width) / (2 * elbow_width), 0.0), 1.0)
        a = angle * s * s * (3 - 2 * s)
        dy = y - height
        return (x * math.cos(a) - dy * math.sin(a), height + x * math.sin(a) + dy * math.cos(a), z)

    for k in range(rings):
        x = -length / 2 + k * step
        for i in range(segments):
            a = 2 * math.pi * i / segments
            vertices.append(bend(x, height + radius * math.sin(a), radius * math.cos(a)))
    for k in range(rings - 1):
        for i in range(segments):
            a, b = k * segments + i, k * segments + (i + 1) % segments
            c, d = a + segments, b + segments
            triangles += [(a, c, d), (a, d, b)]
    for k, x, out in ((0, -length / 2, False), (rings - 1, length / 2, True)):
        centre = len(vertices)
        vertices.append(bend(x, height, 0.0))
        for i in range(segments):
            a, b = k * segments + i, k * segments + (i + 1) % segments
            triangles.append((centre, b, a) if out else (centre, a, b))
    return vertices, triangles


def arm_frames(count=16, swing=math.radians(30.0)):
    """One swing of the arm, `count` frames: the forearm bends up and down by `swing`
    about the straight arm (frame k at angle swing * sin(2 pi k / count)); played at
    8 frames a second and looped, the swing takes 2 s. The frames cover one cycle once,
    so that frame 0 follows the last."""
    os.makedirs("arm", exist_ok=True)
    for k in range(count):
        angle = swing * math.sin(2 * math.pi * k / count)
        write(f"arm/arm_{k:04d}.obj", *arm(angle),
              f"An arm bending at the elbow, frame {k} of {count}: "
              f"{math.degrees(angle):.1f} degrees.")


if __name__ == "__main__":
    arm_frames()
    write("table.obj", *table(), "A table: a 1.2 m x 0.8 m top 75 cm up on four legs.")
    write("turntable.obj", *turntable(), "A turntable: a cylinder 1 m across, 30 cm high.")
