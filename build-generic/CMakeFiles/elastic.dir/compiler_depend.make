# Empty compiler generated dependencies file for elastic.
# This may be replaced when dependencies are built.
