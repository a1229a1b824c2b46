"""Shell model of thin-walled sections: meshes, forms, prestress, pencil, core constraints."""
