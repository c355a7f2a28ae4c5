"""The applications: the `workbench` CLI, controller comparisons and their reports, Figure 17, the paper's
reproduction, the lookahead study and parameter studies. The top layer: nothing of the project imports it."""
