"""The clutch controllers (:mod:`..loop.controller`'s protocol): the slide model's ratchet and locks, the compliant
clutches, finite grip's, the wheels' hub ratchets. They import :mod:`..loop` and :mod:`..builders`."""
