"""The compute-path peers of texflow's fragment passes, re-measured on an NVIDIA GPU.

Not run by CI (it needs CUDA and PyTorch). On the GPU machine:

    python3 examples/peers/gpu_peers.py

prints, for 1M, 4M and 16M entries, a CUB radix sort of (key, id) pairs through torch.sort and
the fire's update (thesis Listing 2: velocity and position of every particle, one step) as
element-wise CUDA work on the same RGBA float32 state, each the median of 21 runs timed with CUDA
events. docs/performance.md sets them beside the fragment passes: what the graphics path costs
against the compute path on the same GPU.
"""

import statistics

import torch


def timed(fn, runs=21):
    start, end = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)
    fn()
    torch.cuda.synchronize()
    times = []
    for _ in range(runs):
        start.record()
        fn()
        end.record()
        torch.cuda.synchronize()
        times.append(start.elapsed_time(end))
    return statistics.median(times)


def main():
    dev = torch.device("cuda")
    print(f"device: {torch.cuda.get_device_name(0)}; torch {torch.__version__}")
    for side in (1024, 2048, 4096):
        n = side * side
        keys = torch.rand(n, device=dev)
        sort_ms = timed(lambda: torch.sort(keys, stable=False))
        pos = torch.rand(n, 4, device=dev)
        vel = torch.rand(n, 4, device=dev) - 0.5
        g = torch.tensor([0.0, 0.4, 0.0, 0.0], device=dev)
        dt = 1.0 / 60.0

        def fire_step():
            # Buoyancy, drag and the life countdown, written back in place like the MRT pass.
            vel.mul_(0.98).add_(g, alpha=dt)
            pos.add_(vel, alpha=dt)
            pos[:, 3].sub_(dt)

        step_ms = timed(fire_step)
        print(
            f"{side}²: torch.sort (CUB radix, keys and indices) {sort_ms:.3f} ms; "
            f"fire update (element-wise, unfused) {step_ms:.3f} ms"
        )


if __name__ == "__main__":
    main()
