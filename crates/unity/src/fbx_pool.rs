//! A thread pool for ufbx on rayon's threads. A binary FBX file keeps its big arrays
//! (positions, indices, normals, UVs) deflate-compressed, and inflating them is most of
//! ufbx's time on real files; given a pool, ufbx hands the arrays out as independent
//! tasks and waits for them before it needs the data, so one large model no longer
//! loads on one core.
//!
//! ufbx calls `run` with a batch of task indices and later `wait` with an index bound.
//! `run` queues the batch and wakes rayon workers to drain the queue; `wait` runs queued
//! tasks itself before it sleeps, and sleeps only on tasks another thread is running
//! (which never block), so a load waiting inside a rayon worker cannot deadlock the
//! pool, however many loads run at once.

use std::collections::VecDeque;
use std::ffi::c_void;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

#[derive(Default)]
struct State {
    /// Tasks handed over and not yet started.
    queued: VecDeque<u32>,
    /// Tasks being run.
    running: Vec<u32>,
}

#[derive(Default)]
pub(crate) struct Pool {
    state: Mutex<State>,
    finished: Condvar,
}

impl Pool {
    fn lock(&self) -> MutexGuard<'_, State> {
        // Tasks are C code and bookkeeping here cannot panic mid-update.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Run one task outside the lock, then mark it finished.
    fn execute(&self, ctx: ufbx::ThreadPoolContext, index: u32) {
        // SAFETY: `ctx` is the context ufbx passed with this batch, and the load it
        // belongs to waits for every task index it handed out before returning.
        unsafe { ufbx::thread_pool_run_task(ctx, index) };
        let mut st = self.lock();
        st.running.retain(|&i| i != index);
        drop(st);
        self.finished.notify_all();
    }

    /// Run queued tasks until none is left (a rayon worker's job).
    fn drain(&self, ctx: ufbx::ThreadPoolContext) {
        loop {
            let mut st = self.lock();
            let Some(index) = st.queued.pop_front() else {
                return;
            };
            st.running.push(index);
            drop(st);
            self.execute(ctx, index);
        }
    }

    /// Return once every task below `max_index` has finished, running queued ones here.
    fn wait(&self, ctx: ufbx::ThreadPoolContext, max_index: u32) {
        let mut st = self.lock();
        loop {
            if let Some(pos) = st.queued.iter().position(|&i| i < max_index) {
                let index = st.queued.remove(pos).unwrap_or(0);
                st.running.push(index);
                drop(st);
                self.execute(ctx, index);
                st = self.lock();
            } else if st.running.iter().any(|&i| i < max_index) {
                st = self.finished.wait(st).unwrap_or_else(|e| e.into_inner());
            } else {
                return;
            }
        }
    }
}

unsafe extern "C" fn run(
    user: *mut c_void,
    ctx: ufbx::ThreadPoolContext,
    _group: u32,
    start: u32,
    count: u32,
) {
    // SAFETY: `user` is the `Arc<Pool>` pointer `thread_opts` made; the Arc outlives
    // the load.
    let pool = unsafe { &*(user as *const Pool) };
    pool.lock()
        .queued
        .extend(start..start.saturating_add(count));
    // SAFETY: as above; each job holds its own count on the Arc.
    let shared = unsafe {
        Arc::increment_strong_count(user as *const Pool);
        Arc::from_raw(user as *const Pool)
    };
    let jobs = (count as usize).min(rayon::current_num_threads());
    for _ in 0..jobs {
        let p = Arc::clone(&shared);
        rayon::spawn(move || p.drain(ctx));
    }
}

unsafe extern "C" fn wait(
    user: *mut c_void,
    ctx: ufbx::ThreadPoolContext,
    _group: u32,
    max_index: u32,
) {
    // SAFETY: see `run`.
    let pool = unsafe { &*(user as *const Pool) };
    pool.wait(ctx, max_index);
}

/// ufbx's thread options backed by `pool`, which must outlive the load.
pub(crate) fn thread_opts(pool: &Arc<Pool>) -> ufbx::ThreadOpts {
    let raw = ufbx::RawThreadPool {
        init_fn: None,
        run_fn: Some(run),
        wait_fn: Some(wait),
        free_fn: None,
        user: Arc::as_ptr(pool) as *mut c_void,
    };
    ufbx::ThreadOpts {
        // SAFETY: the callbacks only dereference `user` while the load runs, and the
        // caller keeps the Arc alive for it.
        pool: ufbx::ThreadPool::Raw(unsafe { ufbx::Unsafe::new(raw) }),
        ..Default::default()
    }
}
