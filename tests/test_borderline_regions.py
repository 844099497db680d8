"""The region-claim generator of uvsym.verify.borderline keeps its promises: borderline boxes at the stated
scales, truth labels that an independent computation confirms, the stated mix of loop kinds."""
