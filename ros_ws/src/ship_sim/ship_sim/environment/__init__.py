"""Wind and wave environment of the plants: MSS environment functions and the disturbance fields."""
