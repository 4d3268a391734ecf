# Empty dependencies file for scaling.
# This may be replaced when dependencies are built.
