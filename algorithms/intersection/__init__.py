"""Surface-surface intersection (000 §29.4, 004 §4-6): triangulation, culling,
triangle intersection, curve topology and refinement onto the exact surfaces."""
