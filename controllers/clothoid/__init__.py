"""The clothoid-based lateral controller of Shaju, Southward & Ahmadian (2024): per-step hyper-clothoid,
Fréchet-distance adaptive lookahead, curvature limits and lead filter. Its modules arrive with issue 4; until then
this package is empty and no controller is registered under "clothoid".
"""
