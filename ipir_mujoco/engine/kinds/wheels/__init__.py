"""The wheeled model: a 3-D robot on sprung wheel legs in a round pipe, a ratchet in every hub; routes."""
