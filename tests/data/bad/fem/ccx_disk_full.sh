#!/bin/sh
# Fake solver: its results are cut short by a full disk; it still exits 0 (as ccx does).
echo " velocities (vx,vy,vz) for set BODYN and time  0.1000000E-03" > impact.dat
echo "fake ccx: write error on impact.dat: No space left on device" >&2
