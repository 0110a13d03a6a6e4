"""What the service keeps on disk: the program store and its uploads, the output area,
the operator data and where the data directory lies (docs/programs.md, docs/operator-data.md).
"""
