"""Stage 3: the normalization methods of seed 000 as span interpolators (placeholder facade)."""
from .spans import METHODS, SpanNormals, span_normals, default_tables
from .counting import OpCounts, count_ops, normalization_ops
