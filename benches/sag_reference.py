"""The bench cloth's sag after 2 s in float32 or float64, on a CUDA GPU through CuPy.

    python3 benches/sag_reference.py 256:float64 700:float64 700:float32

The scene of ../shared/peers/scene.py (N x N particles on a 1 m square, 1 kg, 12-neighbour
springs K = 500 N/m and C = 0.01 N s/m, drag 4/s, the two top corners pinned, semi-implicit
Euler with N substeps per 1/60 s frame), one CUDA thread per particle gathering its 12
springs, so a substep is one launch. It exists to say which answer is right where the
float32 solvers disagree (N = 700): the float64 run is the reference, the float32 run shows
how far rounding alone moves the same arithmetic. Prints one line per run: N, type, sag (m).

A run is N:TYPE, optionally followed by :LINEAR_DRAG (air damping as −rate·v inside the
acceleration, as clothsim does, instead of a factor after it) and :REST_FROM_POS (rest
lengths from the float32 start positions), the variants that were ruled out as causes.
SUB=k takes k times the substeps (a converged answer); TRACE=f prints the sag every f frames.
"""

import math
import os
import sys

import cupy as cp

SOURCE = r"""
extern "C" __global__ void substep(const T* x, const T* v, T* xn, T* vn, int n, double h,
                                   T k, T c, T inv_m, T dt, T damp, T g, const T* x0) {
    int p = blockIdx.x * blockDim.x + threadIdx.x;
    if (p >= n * n) return;
    int j = p / n, i = p % n;
    T px = x[3 * p], py = x[3 * p + 1], pz = x[3 * p + 2];
    if (p == 0 || p == n - 1) {  // pinned: kinematic, at rest
        xn[3 * p] = px; xn[3 * p + 1] = py; xn[3 * p + 2] = pz;
        vn[3 * p] = 0; vn[3 * p + 1] = 0; vn[3 * p + 2] = 0;
        return;
    }
    T ux = v[3 * p], uy = v[3 * p + 1], uz = v[3 * p + 2];
    const int off[12][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1},
                            {1, -1}, {-1, 1}, {2, 0}, {-2, 0}, {0, 2}, {0, -2}};
    T fx = 0, fy = 0, fz = 0;
    for (int o = 0; o < 12; ++o) {
        int di = off[o][0], dj = off[o][1];
        int ii = i + di, jj = j + dj;
        if (ii < 0 || ii >= n || jj < 0 || jj >= n) continue;
        int q = jj * n + ii;
#ifdef REST_FROM_POS
        T ex = x0[3 * q] - x0[3 * p], ey = x0[3 * q + 1] - x0[3 * p + 1], ez = x0[3 * q + 2] - x0[3 * p + 2];
        T rest = sqrt(ex * ex + ey * ey + ez * ez);
#else
        T rest = (T)(h * sqrt((double)(di * di + dj * dj)));
#endif
        T dx = x[3 * q] - px, dy = x[3 * q + 1] - py, dz = x[3 * q + 2] - pz;
        T len = sqrt(dx * dx + dy * dy + dz * dz);
        dx /= len; dy /= len; dz /= len;
        T s = k * (len - rest)
            + c * ((v[3 * q] - ux) * dx + (v[3 * q + 1] - uy) * dy + (v[3 * q + 2] - uz) * dz);
        fx += s * dx; fy += s * dy; fz += s * dz;
    }
#ifdef LINEAR_DRAG
    T rate = (1 - damp) / dt;
    ux = ux + (fx * inv_m - rate * ux) * dt;
    uy = uy + (fy * inv_m - g - rate * uy) * dt;
    uz = uz + (fz * inv_m - rate * uz) * dt;
#else
    ux = (ux + fx * inv_m * dt) * damp;
    uy = (uy + (fy * inv_m - g) * dt) * damp;
    uz = (uz + fz * inv_m * dt) * damp;
#endif
    vn[3 * p] = ux; vn[3 * p + 1] = uy; vn[3 * p + 2] = uz;
    xn[3 * p] = px + ux * dt; xn[3 * p + 1] = py + uy * dt; xn[3 * p + 2] = pz + uz * dt;
}
"""


def sag(n, dtype, defines=()):
    ctype = "double" if dtype == "float64" else "float"
    t = cp.float64 if dtype == "float64" else cp.float32
    head = "".join(f"#define {d}\n" for d in defines)
    kernel = cp.RawKernel(head + "#define T " + ctype + "\n" + SOURCE, "substep")
    h = 1.0 / (n - 1)
    i, j = cp.meshgrid(cp.arange(n), cp.arange(n))  # rows j, columns i
    x0 = cp.stack([-0.5 + i * h, -j * h, cp.zeros((n, n))], axis=-1).reshape(-1, 3)
    x, v = x0.astype(t), cp.zeros((n * n, 3), dtype=t)
    start = x.copy()
    xn, vn = cp.empty_like(x), cp.empty_like(v)
    sub = int(os.environ.get("SUB", "1"))  # substeps per frame: N × SUB
    dt = t(1.0 / (60 * n * sub))
    args = (cp.int32(n), cp.float64(h), t(500.0), t(0.01), t(n * n), dt,
            t(math.exp(-4.0 * float(dt))), t(9.81), start)
    blocks = (n * n + 127) // 128
    a, b = n // 2 - 1, n // 2
    centre = [a * n + a, a * n + b, b * n + a, b * n + b]
    y0 = float(x0[centre, 1].mean())
    trace = int(os.environ.get("TRACE", "0"))
    for frame in range(1, 121):
        for _ in range(n * sub):
            kernel((blocks,), (128,), (x, v, xn, vn) + args)
            x, xn, v, vn = xn, x, vn, v
        if trace and frame % trace == 0:
            y = float(x[centre, 1].astype(cp.float64).mean())
            print(f"  frame {frame} sag {y0 - y:.6f}", flush=True)
    y = float(x[centre, 1].astype(cp.float64).mean())
    return y0 - y, bool(cp.isfinite(x).all())


def main():
    for run in sys.argv[1:] or ["256:float64", "700:float64", "700:float32"]:
        n, dtype, *defines = run.split(":")
        s, finite = sag(int(n), dtype, defines)
        extra = "".join(" " + d for d in defines)
        print(f"{n} {dtype}{extra} sag {s:.6f} m{'' if finite else ' (not finite)'}", flush=True)


if __name__ == "__main__":
    main()
