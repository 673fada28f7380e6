//! A crew: the threads of rayon's current pool held in one job for a whole run of steps, so that a
//! step's team job ([`super::fused`]) is handed to threads that are already running instead of being
//! started and joined as a new rayon job every step.
//!
//! Why: starting and joining a `rayon::broadcast` every step costs about as much as the two threads'
//! imbalance on a step of the sphere beds, several times what handing a task to a running crew costs
//! (figures: `docs/tuning.md`). The thread that waits for the others' part of a broadcast soon sleeps
//! in rayon's idle loop, and waking it is a system call.
//!
//! How: [`Crew::hold`] runs one broadcast for the run. Thread 0 of the pool leads: it runs the caller's
//! closure (the steps). Every other thread serves: it waits for a task, runs its part of it, and while
//! no task is posted it runs whatever rayon work is pending ([`rayon::yield_now`]), so that the passes
//! and list builds that still go through rayon (`for_each_part`, the parallel iterators of a build)
//! find the serving threads. [`Crew::together`] posts a task: every thread of the crew runs `work(k)`
//! with its own index k, as `rayon::broadcast` would, and the lead waits for all of them.
//!
//! While it is held the crew keeps every thread of the pool: rayon jobs of other callers reach the
//! serving threads only through their idle polling, so hold it for a run of one simulation only.

use std::any::Any;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How long a serving thread polls before it also yields its core at each check (a shared host may
/// have descheduled the lead), as in [`super::team`].
const IDLE_SPIN: Duration = Duration::from_micros(100);

/// A task as the serving threads see it: `work` of [`Crew::together`] with its lifetime erased.
#[derive(Clone, Copy)]
struct TaskRef(*const (dyn Fn(usize) + Sync));

// SAFETY: the pointer is to a `Sync` closure that `together` keeps alive until every serving thread has
// reported its part done.
unsafe impl Send for TaskRef {}

/// The threads of one [`Crew::hold`] (see the module docs).
pub(crate) struct Crew {
    threads: usize,
    /// Tasks posted so far, and parts done by serving threads so far (threads − 1 per task).
    posted: AtomicUsize,
    done: AtomicUsize,
    task: Mutex<Option<TaskRef>>,
    /// The first panic of a serving thread's part, passed on to the lead.
    panic: Mutex<Option<Box<dyn Any + Send>>>,
    closing: AtomicBool,
}

impl Crew {
    /// Runs `lead(&crew)` on thread 0 of rayon's current pool while its other threads serve the crew,
    /// and returns what it returns once every thread is back. A panic of `lead` or of a part reaches
    /// the caller (after every thread is back).
    pub(crate) fn hold<R: Send>(lead: impl FnOnce(&Crew) -> R + Send) -> R {
        let crew = Crew {
            threads: rayon::current_num_threads().max(1),
            posted: AtomicUsize::new(0),
            done: AtomicUsize::new(0),
            task: Mutex::new(None),
            panic: Mutex::new(None),
            closing: AtomicBool::new(false),
        };
        let lead = Mutex::new(Some(lead));
        let result = Mutex::new(None);
        rayon::broadcast(|ctx| {
            if ctx.index() == 0 {
                // The serving threads stop when the lead is done, also when it panics.
                let _close = CloseOnDrop(&crew.closing);
                if let Some(lead) = lock(&lead).take() {
                    *lock(&result) = Some(lead(&crew));
                }
            } else {
                crew.serve(ctx.index());
            }
        });
        // The lead ran on thread 0 (a broadcast reaches every thread once), else broadcast panicked.
        let result = result.into_inner().unwrap_or_else(|e| e.into_inner());
        result.expect("the lead of a crew runs on thread 0")
    }

    /// The number of threads of the crew (the pool's).
    pub(crate) fn threads(&self) -> usize {
        self.threads
    }

    /// Runs `work(k)` on every thread k of the crew (this one, the lead, is 0) and returns the results in
    /// thread order. Called by the lead only.
    pub(crate) fn together<R: Send>(&self, work: impl Fn(usize) -> R + Sync) -> Vec<R> {
        let slots: Vec<Mutex<Option<R>>> = (0..self.threads).map(|_| Mutex::new(None)).collect();
        let task = |k: usize| {
            let r = work(k);
            *lock(&slots[k]) = Some(r);
        };
        let task_ref: &(dyn Fn(usize) + Sync) = &task;
        // SAFETY: only the lifetime is erased. The serving threads call the task between the post below
        // and their report that it is done, and this function does not return (nor unwind, see
        // `WaitOnDrop`) before every serving thread has reported.
        let erased: &'static (dyn Fn(usize) + Sync) = unsafe { std::mem::transmute(task_ref) };
        let helpers = self.threads - 1;
        let target = self.done.load(Ordering::Acquire) + helpers;
        *lock(&self.task) = Some(TaskRef(erased as *const _));
        self.posted.fetch_add(1, Ordering::AcqRel);
        {
            let _wait = WaitOnDrop {
                done: &self.done,
                target,
            };
            task(0);
        }
        if let Some(panic) = lock(&self.panic).take() {
            resume_unwind(panic);
        }
        slots
            .into_iter()
            .map(|s| {
                s.into_inner()
                    .unwrap_or_else(|e| e.into_inner())
                    .expect("every thread of the crew ran its part")
            })
            .collect()
    }

    /// Serving thread `k`: runs its part of each posted task, and pending rayon work in between, until
    /// the lead is done.
    fn serve(&self, k: usize) {
        let mut seen = 0;
        let mut idle_since: Option<Instant> = None;
        let mut polls = 0u32;
        loop {
            let posted = self.posted.load(Ordering::Acquire);
            if posted != seen {
                seen = posted;
                let task = *lock(&self.task);
                if let Some(TaskRef(task)) = task {
                    // SAFETY: `together` keeps the task alive until this thread's report below.
                    let run = AssertUnwindSafe(|| unsafe { (*task)(k) });
                    if let Err(panic) = catch_unwind(run) {
                        lock(&self.panic).get_or_insert(panic);
                    }
                }
                self.done.fetch_add(1, Ordering::AcqRel);
                idle_since = None;
                continue;
            }
            if self.closing.load(Ordering::Acquire) {
                return;
            }
            if let Some(rayon::Yield::Executed) = rayon::yield_now() {
                idle_since = None;
                continue;
            }
            std::hint::spin_loop();
            polls = polls.wrapping_add(1);
            if polls.is_multiple_of(64) {
                let since = *idle_since.get_or_insert_with(Instant::now);
                if since.elapsed() > IDLE_SPIN {
                    std::thread::yield_now();
                }
            }
        }
    }
}

/// The lock's value even if a panicking thread poisoned it (every value here is written whole).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Tells the serving threads to stop when dropped (the lead's closure returned or panicked).
struct CloseOnDrop<'a>(&'a AtomicBool);

impl Drop for CloseOnDrop<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

/// Waits, when dropped, until the serving threads have done `target` parts in all: the lead leaves a
/// task only once no serving thread can still read it, also when its own part panicked.
struct WaitOnDrop<'a> {
    done: &'a AtomicUsize,
    target: usize,
}

impl Drop for WaitOnDrop<'_> {
    fn drop(&mut self) {
        let start = Instant::now();
        let mut spins = 0u32;
        while self.done.load(Ordering::Acquire) < self.target {
            std::hint::spin_loop();
            spins = spins.wrapping_add(1);
            if spins.is_multiple_of(64) && start.elapsed() > IDLE_SPIN {
                std::thread::yield_now();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
    }

    #[test]
    fn every_thread_runs_its_part_of_every_task() {
        for threads in [1, 2, 3] {
            let got = pool(threads).install(|| {
                Crew::hold(|crew| {
                    (0..50)
                        .map(|round| crew.together(|k| (k, round, rayon::current_thread_index())))
                        .collect::<Vec<_>>()
                })
            });
            for (round, parts) in got.iter().enumerate() {
                let want: Vec<_> = (0..threads).map(|k| (k, round, Some(k))).collect();
                assert_eq!(parts, &want, "{threads} threads, round {round}");
            }
        }
    }

    #[test]
    fn rayon_work_of_the_lead_runs_while_the_crew_is_held() {
        // A parallel iterator and a broadcast from the lead: the serving threads take their share
        // while they wait for tasks (no deadlock, the same results).
        let (sum, indices) = pool(2).install(|| {
            Crew::hold(|_| {
                let sum: u64 = (0..100_000u64).into_par_iter().map(|x| x % 7).sum();
                let indices = rayon::broadcast(|ctx| ctx.index());
                (sum, indices)
            })
        });
        let want: u64 = (0..100_000u64).map(|x| x % 7).sum();
        assert_eq!((sum, indices), (want, vec![0, 1]));
    }

    #[test]
    fn a_panic_of_a_part_reaches_the_caller_after_the_crew_is_back() {
        let pool = pool(2);
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            pool.install(|| {
                Crew::hold(|crew| {
                    crew.together(|k| {
                        if k == 1 {
                            panic!("part 1 failed");
                        }
                        k
                    })
                })
            })
        }));
        let message = outcome
            .expect_err("the panic of part 1 reaches the caller")
            .downcast::<&str>()
            .map(|m| *m)
            .unwrap_or("another payload");
        assert_eq!(message, "part 1 failed");
        // The pool is usable afterwards: its threads came back.
        assert_eq!(pool.install(|| rayon::broadcast(|ctx| ctx.index())), [0, 1]);
    }
}
