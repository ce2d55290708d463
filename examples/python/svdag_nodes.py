#!/usr/bin/env python3
"""SVDAG node counts against voxel resolution: the scene is voxelized at N³ for each N,
built as an SVO and merged into an SVDAG; nodes and bytes of both are plotted into
OUTPUT/svdag_nodes.png.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/svdag_nodes.py results/py --scene bunny
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt

import gilab


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output", type=pathlib.Path, help="directory for svdag_nodes.png (created if missing)")
    parser.add_argument("--scene", default="cornell", help="built-in name, scene file name or mesh path")
    parser.add_argument("--resolutions", type=int, nargs="+", default=[16, 32, 64, 128, 256])
    args = parser.parse_args()
    args.output.mkdir(parents=True, exist_ok=True)

    scene = gilab.load_scene(args.scene)
    rows = []
    print(f"{'N':>6} {'voxels':>10} {'SVO nodes':>10} {'SVDAG nodes':>12} {'SVO KiB':>9} {'SVDAG KiB':>10}")
    for n in args.resolutions:
        voxels = gilab.voxelize(scene, n)
        svo = gilab.Svo.build(voxels)
        dag = gilab.Svdag.from_svo(svo)
        rows.append((n, len(voxels), svo.node_count, dag.node_count, svo.bytes, dag.bytes, dag.level_node_counts))
        print(f"{n:6d} {len(voxels):10d} {svo.node_count:10d} {dag.node_count:12d} "
              f"{svo.bytes / 1024:9.1f} {dag.bytes / 1024:10.1f}")

    fig, (ax_nodes, ax_levels) = plt.subplots(1, 2, figsize=(9, 3.6))
    resolutions = [r[0] for r in rows]
    ax_nodes.loglog(resolutions, [r[1] for r in rows], "^:", label="occupied voxels", base=2)
    ax_nodes.loglog(resolutions, [r[2] for r in rows], "o-", label="SVO nodes", base=2)
    ax_nodes.loglog(resolutions, [r[3] for r in rows], "s-", label="SVDAG nodes", base=2)
    ax_nodes.set_xlabel("resolution N (N³ voxels)")
    ax_nodes.set_ylabel("count")
    ax_nodes.legend()
    finest = rows[-1]
    ax_levels.semilogy(range(len(finest[6])), finest[6], "s-")
    ax_levels.set_xlabel("octree level (0 = root)")
    ax_levels.set_ylabel(f"SVDAG nodes per level at {finest[0]}³")
    fig.suptitle(f"{scene.name}: sparse voxel DAG against SVO")
    fig.tight_layout()
    out = args.output / "svdag_nodes.png"
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
