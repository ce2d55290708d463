#!/usr/bin/env python3
"""Photon-mapping radius sweep on the Cornell box: error against a path-traced reference
(relMSE, FLIP) and render time for each gather radius, plotted into OUTPUT/radius_sweep.png.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/radius_sweep.py results/py
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt

import gilab


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output", type=pathlib.Path, help="directory for radius_sweep.png (created if missing)")
    parser.add_argument("--scene", default="cornell")
    parser.add_argument("--size", type=int, default=128, help="image width and height")
    parser.add_argument("--photons", type=int, default=65536)
    parser.add_argument("--reference-spp", type=int, default=64)
    parser.add_argument("--radii", type=float, nargs="+", default=[0.01, 0.02, 0.03, 0.05, 0.08, 0.12, 0.18])
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    args.output.mkdir(parents=True, exist_ok=True)

    scene = gilab.load_scene(args.scene)
    reference = gilab.render(scene, "path", width=args.size, height=args.size, spp=args.reference_spp, seed=args.seed)
    errors, flips, times = [], [], []
    print(f"{'radius':>8} {'relMSE':>10} {'FLIP':>8} {'render ms':>10}")
    for radius in args.radii:
        result = gilab.render(scene, "photon", width=args.size, height=args.size, seed=args.seed,
                              settings={"photons": args.photons, "radius": radius})
        errors.append(gilab.relative_mse(result["color"], reference["color"]))
        flips.append(gilab.flip(result["color"], reference["color"]))
        times.append(result.stats["render_ms"])
        print(f"{radius:8.3f} {errors[-1]:10.4f} {flips[-1]:8.4f} {times[-1]:10.1f}")

    fig, (ax_error, ax_time) = plt.subplots(1, 2, figsize=(9, 3.6))
    ax_error.plot(args.radii, errors, "o-", label="relMSE")
    ax_error.plot(args.radii, flips, "s--", label="FLIP")
    ax_error.set_xlabel("gather radius (scene units)")
    ax_error.set_ylabel("error against the path-traced reference")
    ax_error.set_xscale("log")
    ax_error.legend()
    ax_time.plot(args.radii, times, "o-", color="tab:red")
    ax_time.set_xlabel("gather radius (scene units)")
    ax_time.set_ylabel("render time (ms)")
    ax_time.set_xscale("log")
    fig.suptitle(f"{scene.name}: photon radius sweep, {args.photons} photons, {args.size}² pixels "
                 f"(reference: path, {args.reference_spp} spp)")
    fig.tight_layout()
    out = args.output / "radius_sweep.png"
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
