"""Healing of gaps, holes, overlaps and intersections with four-sided bicubic
B-spline approximants joined G0/G1 (Hamann & Jean 1996, paper 001; handbook
§29.3; Soni & Hamann 1993, paper 003)."""
