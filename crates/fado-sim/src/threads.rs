//! How many worker threads a sweep or comparison uses: never more than the machine runs at
//! once ([`std::thread::available_parallelism`]). Simulation points are CPU-bound, so more
//! threads than cores only add switching and memory (2,000 threads took 50× longer than 2 on
//! a 2-core machine).

/// The number of threads to use for `requested` (0: all available), and a warning when more
/// were asked for than the machine has (the callers print it: CLI to stderr, Python as a
/// `RuntimeWarning`).
pub fn capped(requested: usize) -> (usize, Option<String>) {
    let available = std::thread::available_parallelism().map_or(1, |n| n.get());
    cap(requested, available)
}

fn cap(requested: usize, available: usize) -> (usize, Option<String>) {
    if requested == 0 {
        (available, None)
    } else if requested > available {
        (
            available,
            Some(format!(
                "{requested} threads asked for but this machine runs {available} at once: using {available}"
            )),
        )
    } else {
        (requested, None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_above_the_available_parallelism_are_capped_with_a_warning() {
        assert_eq!(cap(0, 4), (4, None));
        assert_eq!(cap(3, 4), (3, None));
        assert_eq!(cap(4, 4), (4, None));
        let (n, warning) = cap(2000, 4);
        assert_eq!(n, 4);
        assert!(warning.unwrap().contains("2000 threads"));
        let (n, _) = capped(usize::MAX);
        assert!(n >= 1 && n <= std::thread::available_parallelism().unwrap().get());
    }
}
