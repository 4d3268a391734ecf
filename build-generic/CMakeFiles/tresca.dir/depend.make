# Empty dependencies file for tresca.
# This may be replaced when dependencies are built.
