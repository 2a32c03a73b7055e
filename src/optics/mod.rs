//! The reflection model of METHOD.md §4. (Being written: see the optics work item.)
