"""The tracker at run time: the subject tracker and make_tracker, its estimate, filters, appearance
models and box geometry."""
