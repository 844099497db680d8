"""Zonotopes of uvsym.sets.zonotope, operation by operation: sums, images, interval hulls, containment and their
errors, with expected values worked out by hand."""
