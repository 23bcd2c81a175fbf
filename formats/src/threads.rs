//! The worker thread pool every program starts: from `--threads`, else from rayon's own
//! `RAYON_NUM_THREADS`, else one thread per core — with both numbers checked, since rayon
//! takes any count it is given and silently ignores a value it cannot parse.

/// Most worker threads: each has its own stack, and a hundred thousand spent minutes being
/// created before running out of memory.
pub const MAX_THREADS: usize = 1024;

/// The environment variable rayon reads when no count is given.
const VAR: &str = "RAYON_NUM_THREADS";

/// The number of threads asked for: `threads` (a `--threads` value), else
/// `RAYON_NUM_THREADS` when set (rayon's 0 or empty meaning one per core: `None`), else
/// `None`. The error names the option or variable and its value.
pub fn requested(threads: Option<usize>, env: Option<&str>) -> Result<Option<usize>, String> {
    if let Some(n) = threads {
        return match n {
            0 => Err("--threads 0: at least one thread is needed".into()),
            n if n > MAX_THREADS => Err(format!("--threads {n}: at most {MAX_THREADS}")),
            n => Ok(Some(n)),
        };
    }
    let Some(value) = env.map(str::trim) else {
        return Ok(None);
    };
    match value.parse::<usize>() {
        _ if value.is_empty() => Ok(None),
        Ok(0) => Ok(None),
        Ok(n) if n <= MAX_THREADS => Ok(Some(n)),
        Ok(n) => Err(format!("{VAR}={n}: at most {MAX_THREADS} threads")),
        Err(_) => Err(format!("{VAR}={value:?} is not a number of threads")),
    }
}

/// Start the global pool with [`requested`]'s count, read from this process's `threads`
/// and environment. Call it before any parallel work: the pool starts once.
pub fn start(threads: Option<usize>) -> Result<(), String> {
    let env = std::env::var_os(VAR).map(|v| v.to_string_lossy().into_owned());
    let Some(n) = requested(threads, env.as_deref())? else {
        return Ok(());
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|e| format!("cannot start {n} worker threads: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_taken_from_the_option_then_the_variable_and_checked() {
        assert_eq!(requested(Some(3), Some("500")), Ok(Some(3)));
        assert_eq!(requested(None, Some(" 2 ")), Ok(Some(2)));
        assert_eq!(requested(None, Some("1024")), Ok(Some(1024)));
        for all_cores in [None, Some(""), Some("0")] {
            assert_eq!(requested(None, all_cores), Ok(None));
        }
        assert_eq!(
            requested(Some(0), None),
            Err("--threads 0: at least one thread is needed".into())
        );
        assert_eq!(
            requested(Some(100_000), None),
            Err("--threads 100000: at most 1024".into())
        );
        assert_eq!(
            requested(None, Some("100000")),
            Err("RAYON_NUM_THREADS=100000: at most 1024 threads".into())
        );
        assert_eq!(
            requested(None, Some("two")),
            Err("RAYON_NUM_THREADS=\"two\" is not a number of threads".into())
        );
    }
}
