# Empty dependencies file for tresca_core.
# This may be replaced when dependencies are built.
