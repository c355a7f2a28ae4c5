"""Tuning tools: open-loop data generation now; lag identification, lead-filter design and rollover limits next."""
