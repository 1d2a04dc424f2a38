"""The steps that turn a GranularModel into a LAMMPS job (``translate.granular_job`` runs them):

``schedule``  run length, save steps, the script's run/frame/delete actions
``spheres``   which spheres are simulated, their LAMMPS types, activity-end deletions
``walls``     how each geometry / plane is represented; its region, fix and variable commands
``geometry``  wall shapes, rigid-motion kinematics and wall-particle tiling (numpy only)
``tiles``     frozen wall particles of tiled geometries, placed within reach of the spheres
``box``       the LAMMPS box, neighbour bins, domain removal and reach checks
``bonds``     solid bonds simulated and their bond types
``contacts``  contact laws as pair_coeff / wall/gran arguments, rolling springs
``data``      the data file
"""
