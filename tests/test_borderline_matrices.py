"""The matrix and identity generators of uvsym.verify.borderline keep their promises: exact spectra, rates at
the stated distances from the boundary, unimodular conjugations, identities false where and by how much they say."""
