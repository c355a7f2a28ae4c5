"""Tuning tools: open-loop vehicle logs, identification of the steering lag (Eq. 5), design of the lead filter
(Eq. 6), curvature limits from rollover (section 4) and a lead filter scheduled on speed; the `tuning` CLI."""
