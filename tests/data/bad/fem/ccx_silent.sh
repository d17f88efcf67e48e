#!/bin/sh
# Fake solver: exits 0 without writing any result (the all-node velocity print is missing).
echo "fake ccx: nothing computed"
