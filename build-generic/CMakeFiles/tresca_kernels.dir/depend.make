# Empty dependencies file for tresca_kernels.
# This may be replaced when dependencies are built.
