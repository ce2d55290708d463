"""No leak across renders: 100 renders whose films, technique and arrays are all
dropped must leave the resident set where it was (read from /proc/self/statm)."""
import gc
import os

import gilab

PAGE = os.sysconf("SC_PAGE_SIZE")
# Each render below allocates about 1.2 MiB of films alone (128² pixels, 3-channel float
# layers), so leaking even just the films of 100 renders would add over 100 MiB.
ALLOWED_GROWTH = 24 << 20


def resident_bytes():
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * PAGE


def one_render(scene, i):
    technique, settings = ("photon", {"photons": 4096}) if i % 2 else ("path", {"spp": 1})
    result = gilab.render(scene, technique, width=128, height=128, seed=i, settings=settings, threads=2)
    color = result["color"]  # a view that holds the film until it goes
    return float(color.mean()) + len(result.stats)


def test_100_renders_do_not_grow_the_resident_set(cornell):
    for i in range(10):  # allocator pools, TBB workers and Embree reach their steady size
        one_render(cornell, i)
    gc.collect()
    before = resident_bytes()
    for i in range(100):
        one_render(cornell, i)
    gc.collect()
    growth = resident_bytes() - before
    assert growth < ALLOWED_GROWTH, f"resident set grew by {growth / 2**20:.1f} MiB over 100 renders"
