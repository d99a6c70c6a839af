"""Core: units, the Earth model, geodesy, path segments and the data contracts (states, navigation
solution, guidance output, timeseries columns). Imports nothing else of the package."""
