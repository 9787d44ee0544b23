"""Environmental disturbances: ocean waves (and wind), pure numpy/scipy ports of MSS."""
