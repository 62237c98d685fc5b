"""Lumped function-block models of the paper (eq. 7-14).

Only the closed-form fin solution (eq. 14, :mod:`lumped.fin`) exists so far; the
5-, 11- and N-node networks are issue 4.
"""
