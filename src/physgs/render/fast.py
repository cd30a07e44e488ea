"""Fast CPU compositing (numba kernels). Temporary: routes to the reference until the kernels land."""
from physgs.render.reference import composite_reference as composite_fast  # noqa: F401
