"""Model-predictive lateral controllers: a CasADi nonlinear bicycle-model MPC (the paper's baseline) and an OSQP
linear time-varying MPC. They arrive with issue 5; until then this package is empty and registers nothing.
"""
