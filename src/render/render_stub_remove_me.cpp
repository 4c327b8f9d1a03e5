// Placeholder translation unit until the first render source lands.
