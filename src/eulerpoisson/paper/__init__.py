"""The paper machine-checked: SymPy derivation (:mod:`.symbolic`), the transcribed formulas (:mod:`.entries`) and the audit (:mod:`.audit`)."""
