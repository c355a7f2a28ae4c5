"""The base layer: errors, reference paths and their search, waypoint files, clothoid chains, typed tables and the
input/output file boundary. It imports nothing else of the project."""
