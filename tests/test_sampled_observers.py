"""Sampled (discrete-time) actuator-fault observers of uvsym.observers.discrete: the pieces of the step, the
residue dropped from the update, initial states and labels, with expected values worked out by hand."""
