file(REMOVE_RECURSE
  "libtresca_kernels.a"
)
