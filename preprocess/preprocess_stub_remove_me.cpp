// Placeholder translation unit until the first preprocess source lands.
