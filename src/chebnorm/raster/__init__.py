"""Stage 4: meshes, scan-line spans, shading modes and image metrics."""
