"""File formats: the toolkit's own .npz (`lcp.load`, lcp/io/load.py; `.save` of lcp.LCP and
lcp.MLCP) and Siconos's text formats (siconos.py); safe writing and reading (files.py)."""
