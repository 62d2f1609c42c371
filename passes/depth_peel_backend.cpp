// Filled in with the depth-peeling backend.
