"""Route construction (waypoints, arcs, fillets, parametric curves), chart-based optimal routes, and the route node."""
