# Empty dependencies file for mg_scaling.
# This may be replaced when dependencies are built.
