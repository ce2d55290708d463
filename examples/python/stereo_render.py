#!/usr/bin/env python3
"""A stereo pair through an HMD rig: both eyes rendered in one call (so the photon
technique can reuse the left eye's shading for the right), saved as OUTPUT/left.png and
OUTPUT/right.png.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/stereo_render.py results/py
"""
import argparse
import pathlib

import gilab


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output", type=pathlib.Path, help="directory for left.png and right.png (created if missing)")
    parser.add_argument("--scene", default="cornell")
    parser.add_argument("--hmd", default="vive", help="headset preset (see gilab.hmd_presets())")
    parser.add_argument("--technique", default="photon")
    parser.add_argument("--width", type=int, default=270, help="per-eye width (default: a quarter of the Vive's)")
    parser.add_argument("--height", type=int, default=300)
    parser.add_argument("--ipd", type=float, default=None, help="inter-pupillary distance in metres")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--exposure", type=float, default=0.0)
    args = parser.parse_args()
    args.output.mkdir(parents=True, exist_ok=True)

    scene = gilab.load_scene(args.scene)
    rig = gilab.hmd(args.hmd)
    rig.pose = scene.head_pose()  # where `gilab render --hmd` puts the head
    rig.resolution = (args.width, args.height)
    if args.ipd is not None:
        rig.ipd = args.ipd
    settings = {"stereo_reuse": True} if args.technique == "photon" else {}
    result = gilab.render(scene, args.technique, camera=rig, seed=args.seed, settings=settings)
    for eye in ("left", "right"):
        path = args.output / f"{eye}.png"
        getattr(result, eye).write_png(path, exposure=args.exposure)
        print(f"wrote {path}")
    print(f"{args.technique}, {rig.preset['display_name']}, {args.width}×{args.height} per eye, "
          f"IPD {rig.ipd * 1000:.0f} mm: render {result.render_seconds * 1000:.1f} ms")


if __name__ == "__main__":
    main()
