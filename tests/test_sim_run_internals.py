"""The simulation runner's internals (uvsym.sim.run): decision columns, the stepper, chunk checks, substitutions,
the first non-finite sample and the sizes it prints, with expected values worked out by hand."""
