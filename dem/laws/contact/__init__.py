"""Contact laws of particles that move: each a material (its parameters, checked) and the compiled kernels of the
force between two particles and between a particle and a wall."""
