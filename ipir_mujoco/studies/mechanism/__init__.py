"""Studies of one part of the mechanism at a time: real clutches' engagement loads, speed control of the
crank, passing a bend."""
