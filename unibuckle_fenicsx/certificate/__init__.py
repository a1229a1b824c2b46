"""Certificates of global optimality: reduced inertia and copositivity bounds."""
