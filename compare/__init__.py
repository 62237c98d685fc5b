"""The comparison harness and the command line (``spindle-verify``).

This package sits on top: it may import ``reference``, ``lumped``, ``meshes`` and
``spindle``; none of them imports it.
"""
