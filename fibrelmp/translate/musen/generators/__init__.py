"""cmusen's generator components: PACKAGE_GENERATOR (``package``), BONDS_GENERATOR
(``bonds``) and SNAPSHOT_GENERATOR (``snapshot``), run as a script's jobs (``jobs``, ``steps``) on the scene of a ``.mdem`` file
(``scene``), with the triangle-mesh geometry they need (``mesh``)."""
