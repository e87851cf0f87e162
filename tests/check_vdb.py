#!/usr/bin/python3
"""dump --vdb: each float volume dumped as .npy (q, T, T_sky) is also an OpenVDB fog volume that reads back, through
Debian's python3-openvdb, as the .npy bit for bit, with the transform that puts voxel (i, j, k) at its centre.

Usage: check_vdb.py CLOUDBENCH OUT_DIR
On a one-voxel grid and on an odd-sized one (5 x 3 x 7, a voxel size and an origin that are not round), the sky
light on (so T_sky is dumped too). Exit 77 (a skip) where python3-openvdb is not installed.
"""
import os
import shutil
import struct
import subprocess
import sys

try:
    import numpy
    import pyopenvdb
except ImportError as e:
    print("vdb: unsupported here: %s (apt-get install python3-openvdb python3-numpy)" % e)
    sys.exit(77)

cli, out = sys.argv[1], sys.argv[2]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)


def fail(message):
    sys.exit("vdb: " + message)


def bits(value):
    return struct.unpack("<I", struct.pack("<f", value))[0]


CASES = {
    "one-voxel": ["--set", "grid.size=[1,1,1]", "--set", "grid.voxel_size=50", "--set", "grid.origin=[0,0,0]"],
    "odd": ["--set", "grid.size=[5,3,7]", "--set", "grid.voxel_size=37.5", "--set", "grid.origin=[-120.25,7,1500.5]"],
}
SKY = ["--set", 'lighting.sky={"elevation_deg":60,"azimuth_deg":10,"color":[0.5,0.6,1],"intensity":0.3}',
       "--set", 'stages=["region","ca","smooth","density","shade","shade_sky","shadow","render_splat"]']
checked = 0
for name, grid in CASES.items():
    folder = os.path.join(out, name)
    p = subprocess.run([cli, "dump", "ci-small", "--steps", "2", "--vdb", "--quiet", "--out", folder] + grid + SKY,
                       capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        fail("%s: dump failed (exit %d): %s" % (name, p.returncode, p.stderr))
    voxel = float([g for g in grid if g.startswith("grid.voxel_size=")][0].split("=")[1])
    origin = [float(v) for v in [g for g in grid if g.startswith("grid.origin=")][0].split("=")[1].strip("[]").split(",")]
    step = os.path.join(folder, "step_0001")
    stems = sorted(f[:-4] for f in os.listdir(step) if f.endswith(".vdb"))
    if stems != ["T", "T_sky", "q"]:
        fail("%s: .vdb files %s, expected T, T_sky and q" % (name, stems))
    for stem in stems:
        want = numpy.load(os.path.join(step, stem + ".npy"))  # (nz, ny, nx)
        grids, _ = pyopenvdb.readAll(os.path.join(step, stem + ".vdb"))
        if len(grids) != 1 or grids[0].name != stem:
            fail("%s %s: grids %s, expected one named %s" % (name, stem, [g.name for g in grids], stem))
        g = grids[0]
        if g.gridClass != "fog volume":
            fail("%s %s: grid class %s, not a fog volume" % (name, stem, g.gridClass))
        reader = g.getConstAccessor()
        nz, ny, nx = want.shape
        for k in range(nz):
            for j in range(ny):
                for i in range(nx):
                    got = reader.getValue((i, j, k))
                    if bits(got) != bits(float(want[k, j, i])):
                        fail("%s %s: voxel (%d, %d, %d) reads %r, the .npy holds %r" % (name, stem, i, j, k, got,
                                                                                      float(want[k, j, i])))
        # The transform: index (0, 0, 0) is the first voxel's centre, one index step is one voxel.
        centre = [o + 0.5 * voxel for o in origin]
        if list(g.transform.indexToWorld((0, 0, 0))) != centre:
            fail("%s %s: voxel (0, 0, 0) at %s, expected its centre %s" % (name, stem,
                                                                      g.transform.indexToWorld((0, 0, 0)), centre))
        if list(g.transform.voxelSize()) != [voxel] * 3:
            fail("%s %s: voxel size %s, expected %s" % (name, stem, g.transform.voxelSize(), voxel))
        far = (nx - 1, ny - 1, nz - 1)
        if list(g.transform.indexToWorld(far)) != [c + f * voxel for c, f in zip(centre, far)]:
            fail("%s %s: voxel %s at %s" % (name, stem, far, g.transform.indexToWorld(far)))
        checked += 1
print("vdb: ok (%d volumes read back bit for bit with their transforms)" % checked)
