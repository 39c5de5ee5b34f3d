//! Paths: lines, arcs, NURBS, built-in shapes and feed-rate interpolation (in progress).
