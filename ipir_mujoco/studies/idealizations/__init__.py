"""The idealization atlas: where each of the paper's idealizations can be trusted over a box of designs
(its design space, evaluations, adaptive placement and Gaussian-process surrogate)."""
