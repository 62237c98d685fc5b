"""The independent cross-check of the reference against CalculiX (``ccx``): decks written from
the reference's assembled data (:mod:`.deck`), ccx run (:mod:`.ccx`), its results read
(:mod:`.frd`), and the comparison with the reference and its quadrature twin (:mod:`.check`,
:mod:`.twin`). docs/crosscheck.md has the figures."""

from compare.crosscheck.ccx import CCX_MISSING, run_ccx
from compare.crosscheck.check import CrosscheckResult, crosscheck
from compare.crosscheck.deck import export_deck, export_elastic_deck
from compare.crosscheck.frd import read_frd

__all__ = ["CCX_MISSING", "CrosscheckResult", "crosscheck", "export_deck",
           "export_elastic_deck", "read_frd", "run_ccx"]
