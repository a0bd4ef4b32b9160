#!/usr/bin/env python3
"""Writes the files of cases/sfz_building_3d.toml: the flume's bed, the dam's blocks and the
building of Soares-Frazao & Zech (2007), "Experimental study of dam-break flow against an
isolated obstacle", J. Hydraul. Res. 45 (sup1), 27-36 (doi 10.1080/00221686.2007.9521830), as
../shared/validation/README.md gives the experiment's sketch.

World frame (the files'): x along the flume from its upstream end, y across from the wall on
the gauges' negative side, z up from the flat bottom. The case puts its origin at the gate's
downstream face on the flume's axis (the gauges' frame): terrain.origin_m = [7.55, 1.80, 0].

  python3 tools/sfz_building_files.py    # rewrites cases/sfz_building/
"""
import json
import math
import os

LENGTH, WIDTH = 35.80, 3.60
SLOPE_WIDTH, SLOPE_RISE = 0.34, 0.155   # at each side wall; flat bottom 2.92 m wide
RESERVOIR, DAM = 6.75, 0.80            # reservoir length (the README's choice), dam thickness
GATE = 1.00                            # gate width, in the dam's middle
GATE_FACE = RESERVOIR + DAM            # x of the gate's downstream face: the gauges' x = 0
AXIS = WIDTH / 2                       # y of the gate's centre line: the gauges' y = 0
# Building corners in the gauges' frame (README).
BUILDING = [(3.440, -0.050), (3.791, 0.669), (4.150, 0.494), (3.800, -0.225)]
HERE = os.path.join(os.path.dirname(__file__), "..", "cases", "sfz_building")


def bed(y):
    """The bed's elevation across the flume: flat, rising linearly to 0.155 m at each wall."""
    edge = min(y, WIDTH - y)
    return SLOPE_RISE * max(0.0, (SLOPE_WIDTH - edge) / SLOPE_WIDTH)


def write_bed():
    """An ESRI ASCII grid of the bed, cells 0.2 m along the flume and 0.02 m across (the
    slopes' breaks fall on cell centres' lines within half a cell)."""
    dx, dy = 0.2, 0.02
    ncols, nrows = round(LENGTH / dx) + 1, round(WIDTH / dy)
    lines = [f"ncols {ncols}", f"nrows {nrows}", "xllcorner 0", "yllcorner 0",
             f"dx {dx}", f"dy {dy}", "NODATA_value -9999"]
    for row in range(nrows - 1, -1, -1):          # rows from the north (largest y) first
        z = bed((row + 0.5) * dy)
        lines.append(" ".join(f"{z:.5f}" for _ in range(ncols)))
    with open(os.path.join(HERE, "bed.asc"), "w") as f:
        f.write("\n".join(lines) + "\n")


def write_dam():
    """The dam's two blocks beside the gate as GeoJSON footprints in the world frame, 0.7 m
    high (above the reservoir's 0.4 m)."""
    half = (WIDTH - GATE) / 2
    blocks = [(0.0, half), (WIDTH - half, WIDTH)]
    features = []
    for y0, y1 in blocks:
        ring = [[RESERVOIR, y0], [GATE_FACE, y0], [GATE_FACE, y1], [RESERVOIR, y1],
                [RESERVOIR, y0]]
        features.append({"type": "Feature", "properties": {"height": 0.7},
                         "geometry": {"type": "Polygon", "coordinates": [ring]}})
    with open(os.path.join(HERE, "dam.geojson"), "w") as f:
        json.dump({"type": "FeatureCollection", "features": features}, f, indent=1)
        f.write("\n")


def write_building():
    """The building as a closed STL box 0.80 x 0.40 m in plan and 0.8 m high, centred on the
    origin in plan, its long side along x, from 0.05 m below the bed: the case turns it by
    64 degrees about z and moves it onto its corners (rotate_deg, translate_m)."""
    lx, ly, z0, z1 = 0.80, 0.40, -0.05, 0.75
    v = [(sx * lx / 2, sy * ly / 2, z) for z in (z0, z1) for sy in (-1, 1) for sx in (-1, 1)]
    # Corners 0-3 at the bottom, 4-7 at the top; each face counter-clockwise from outside.
    faces = [(0, 2, 3), (0, 3, 1), (4, 5, 7), (4, 7, 6), (0, 1, 5), (0, 5, 4),
             (2, 6, 7), (2, 7, 3), (0, 4, 6), (0, 6, 2), (1, 3, 7), (1, 7, 5)]
    out = ["solid sfz_building"]
    for a, b, c in faces:
        out += ["  facet normal 0 0 0", "    outer loop"]
        out += [f"      vertex {v[k][0]:.6f} {v[k][1]:.6f} {v[k][2]:.6f}" for k in (a, b, c)]
        out += ["    endloop", "  endfacet"]
    out.append("endsolid sfz_building")
    with open(os.path.join(HERE, "building.stl"), "w") as f:
        f.write("\n".join(out) + "\n")


def building_placement():
    """The turn and move that put the box on the README's corners, to check the case's."""
    cx = sum(p[0] for p in BUILDING) / 4
    cy = sum(p[1] for p in BUILDING) / 4
    (x0, y0), (x1, y1) = BUILDING[0], BUILDING[1]
    return math.degrees(math.atan2(y1 - y0, x1 - x0)), (cx, cy)


if __name__ == "__main__":
    os.makedirs(HERE, exist_ok=True)
    write_bed()
    write_dam()
    write_building()
    angle, centre = building_placement()
    print(f"building: rotate_deg = [0, 0, {angle:.2f}], translate_m = "
          f"[{centre[0]:.5f}, {centre[1]:.5f}, 0]")
