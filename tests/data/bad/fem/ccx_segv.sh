#!/bin/sh
# Fake solver for tests/data/bad/cases.tsv: dies of SIGSEGV (as ccx did when two runs shared a deck).
kill -SEGV $$
