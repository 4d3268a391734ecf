# Empty compiler generated dependencies file for roofline.
# This may be replaced when dependencies are built.
