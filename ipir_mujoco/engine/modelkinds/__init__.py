"""The model kinds (:mod:`.kinds`: slides, slides on finite grip, wheels), each one object, and what a kind
chooses for its runs: the automatic timestep, the loop's friction rows, a route's watch, the clutch-option
check. They import the controllers, the loop and the builders."""
