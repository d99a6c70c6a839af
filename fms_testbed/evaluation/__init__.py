"""Evaluation: flight errors (FTE/NSE/PDE/TSE), constraint compliance, database invariants
(``procedures check``) and vertical-law comparisons."""
