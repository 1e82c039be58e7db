"""The slide model on wheels of finite grip: a carriage per module on the wall, held by friction G_i."""
