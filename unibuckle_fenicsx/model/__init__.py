"""The plate problem: mesh, prestress, Reissner-Mindlin plate, obstacle contact, pencil."""
