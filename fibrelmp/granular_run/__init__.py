"""What a granular run (MUSEN scenes, cmusen scripts, DEMDF) is made of, shared by those
formats' homes: ``request`` (the job builder and the ``RunRequest`` of one simulation),
``frames`` (``FrameBuilder``: the saved dumps -> ``GranularFrame``), ``spool`` (on-disk frames
of a cmusen simulation that a later job exports).  It sits below the homes and above ``post``
(its frames read LAMMPS dumps); it never imports the pipeline, which executes the plans."""
