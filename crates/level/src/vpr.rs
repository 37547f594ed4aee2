//! TODO(issue 2)
