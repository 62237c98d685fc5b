"""The synthetic bench: runs made from the FEM reference with known effects, causes outside
the library, a spindle drawn away from its spec, and logging as a bench logs (bench.py,
outside.py, mismatch.py), and effects injected into recorded runs (inject.py). Test data for
the fit, which never imports this package: each effect declares its own injection
(compare.fit.effects)."""
