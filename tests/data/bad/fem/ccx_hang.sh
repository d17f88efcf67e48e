#!/bin/sh
# Fake solver: hangs (a child keeps its process group alive too); only the timeout ends it.
sleep 60 &
sleep 60
