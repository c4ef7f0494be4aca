"""Writes copies of the peer scripts (../shared/peers) that can run on a CUDA GPU.

    python3 benches/peers_on_gpu.py ../shared/peers /tmp/gpu-peers
    cd /tmp/gpu-peers && PEER_DEVICE=cuda python3 warp_cloth.py --n 512 --variant gather
    PEER_ARCH=cuda python3 taichi_cloth.py --n 512

The peers are written for the CPU. The copies take Warp's device from PEER_DEVICE and
Taichi's arch from PEER_ARCH (both default to the CPU), and Warp's frame waits for the
device before its clock stops (Taichi's already calls ti.sync()), so a frame's time is
the GPU's work, not the time to queue it. Nothing else changes: same scene, same kernels.
"""

import pathlib
import sys


def main():
    src, dst = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    dst.mkdir(parents=True, exist_ok=True)
    for name in ("scene.py", "numpy_cloth.py"):
        (dst / name).write_text((src / name).read_text())

    warp = (src / "warp_cloth.py").read_text()
    frame_end = "            simulate()\n\n    timer, done"
    if 'dev = "cpu"' not in warp or frame_end not in warp:
        sys.exit("warp_cloth.py is not the version this patch knows")
    warp = warp.replace('dev = "cpu"', 'dev = os.environ.get("PEER_DEVICE", "cpu")')
    warp = warp.replace(frame_end, "            simulate()\n        wp.synchronize_device(dev)\n\n    timer, done")
    (dst / "warp_cloth.py").write_text(warp)

    taichi = (src / "taichi_cloth.py").read_text()
    if "arch=ti.cpu" not in taichi or "ti.sync()" not in taichi:
        sys.exit("taichi_cloth.py is not the version this patch knows")
    taichi = "import os\n" + taichi.replace("arch=ti.cpu", 'arch=getattr(ti, os.environ.get("PEER_ARCH", "cpu"))')
    (dst / "taichi_cloth.py").write_text(taichi)
    print("GPU-capable peers written to", dst)


if __name__ == "__main__":
    main()
