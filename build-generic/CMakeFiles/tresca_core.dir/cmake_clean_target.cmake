file(REMOVE_RECURSE
  "libtresca_core.a"
)
