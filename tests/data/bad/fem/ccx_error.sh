#!/bin/sh
# Fake solver: refuses the deck as ccx does, with an *ERROR line and exit code 201.
echo " *ERROR in calinput: no material was assigned"
exit 201
