"""The command line (``snakehead``) and the pipeline behind it: plan -> simulate -> compare -> figures -> report."""
