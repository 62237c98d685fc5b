"""The independent cross-check of the reference against CalculiX (ccx)."""
