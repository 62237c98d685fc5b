"""The independent cross-check of the reference against CalculiX (``ccx``): the P2 mesh in
ccx numbering (:mod:`.ccx_mesh`), the heat-transfer and elastic data taken from the reference
(:mod:`.thermal_data`, :mod:`.elastic_data`), the decks written (:mod:`.deck`), ccx run
(:mod:`.ccx`), its results read (:mod:`.frd`), the reference with ccx's quadrature
(:mod:`.twin`), and the comparison (:mod:`.check`) with its result (:mod:`.result`).
docs/crosscheck.md has the figures."""

from compare.crosscheck.ccx import CCX_MISSING, run_ccx
from compare.crosscheck.check import crosscheck
from compare.crosscheck.deck import export_deck, export_elastic_deck
from compare.crosscheck.frd import read_frd
from compare.crosscheck.result import CrosscheckResult

__all__ = ["CCX_MISSING", "CrosscheckResult", "crosscheck", "export_deck",
           "export_elastic_deck", "read_frd", "run_ccx"]
