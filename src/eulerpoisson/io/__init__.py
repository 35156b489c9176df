"""Files: atomic writes (:mod:`.atomic`) and streaming of long runs to Zarr (:mod:`.stream`)."""
