"""The model of the equations of motion: bodies (:mod:`.body`), torques, and the paper's formulations (:mod:`.formulations`)."""
