//! `--pin none|compact|spread`: on which logical CPUs a run's threads run.
//!
//! `none` (the default, and what the seed paper measured) leaves placement to the operating
//! system. `compact` and `spread` pin worker thread i to CPU `order[i % len]` of the
//! [`Topology::order`] of the process's allowed CPUs: `compact` fills the SMT siblings of one
//! physical core before the next, `spread` puts one thread on each physical core before using
//! any sibling. The calling (main) thread is pinned to `order[0]` for the run, and its own
//! mask is restored afterwards, so that a later unpinned run (and every thread it starts,
//! which inherits the mask) is not confined to one CPU.
//!
//! Before anything runs, [`placement`] checks that the operating system lets this process run
//! on every CPU of the order (by moving the calling thread onto each in turn): a refusal is an
//! error naming the CPU, never silently ignored. A worker whose pinning fails nevertheless (a
//! CPU taken offline mid-run) is recorded, and [`Pinned::finish`] turns it into an error.
//!
//! The OS calls go through `nix` (safe wrappers of `sched_setaffinity`); on other systems than
//! Linux, `compact` and `spread` are errors.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};

use anyhow::bail;
use sph_strategies::Placement;

use crate::topology::{Pin, Topology};

/// `usize::MAX`, or the CPU a worker failed to pin itself to (its first failure).
static FAILED_CPU: AtomicUsize = AtomicUsize::new(usize::MAX);

/// The machine's topology, read once (before any thread of this process is pinned: it is
/// read from the affinity mask of the thread that asks first).
pub fn machine_topology() -> &'static Topology {
    static TOPOLOGY: OnceLock<Topology> = OnceLock::new();
    TOPOLOGY.get_or_init(Topology::detect)
}

/// The placement of `pin`: [`Placement::OS`] for `none`; otherwise a hook pinning worker i to
/// `order[i % len]`, once the operating system has accepted every CPU of the order.
pub fn placement(pin: Pin) -> anyhow::Result<Placement> {
    let Some(order) = order(pin)? else {
        return Ok(Placement::OS);
    };
    static HOOKS: OnceLock<Mutex<HashMap<Pin, Placement>>> = OnceLock::new();
    let mut hooks = HOOKS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    if let Some(&p) = hooks.get(&pin) {
        return Ok(p);
    }
    os::check(pin, order)?;
    let hook = move |worker: usize| {
        let cpu = order[worker % order.len()];
        if os::pin_current(cpu).is_err() {
            let _ =
                FAILED_CPU.compare_exchange(usize::MAX, cpu, Ordering::SeqCst, Ordering::SeqCst);
        }
    };
    // One hook per pin mode for the whole process: leaked on purpose (at most two).
    let cpus = order.iter().collect::<std::collections::HashSet<_>>().len();
    let placement = Placement::new(Box::leak(Box::new(hook)), cpus);
    hooks.insert(pin, placement);
    Ok(placement)
}

/// The CPUs of `pin`'s order (`None` for `none`), leaked once per mode.
fn order(pin: Pin) -> anyhow::Result<Option<&'static [usize]>> {
    static ORDERS: OnceLock<Mutex<HashMap<Pin, &'static [usize]>>> = OnceLock::new();
    if pin == Pin::None {
        return Ok(None);
    }
    let mut orders = ORDERS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    if let Some(&o) = orders.get(&pin) {
        return Ok(Some(o));
    }
    let Some(order) = machine_topology().order(pin).filter(|o| !o.is_empty()) else {
        bail!("--pin {pin}: the CPUs this process may run on are unknown here");
    };
    let order: &'static [usize] = Vec::leak(order);
    orders.insert(pin, order);
    Ok(Some(order))
}

/// The calling thread, pinned for one run (see the module docs); restores its mask when
/// dropped.
#[must_use = "the calling thread stays pinned only while this lives"]
pub struct Pinned {
    restore: Option<os::Mask>,
}

impl Pinned {
    /// Pins the calling thread as worker 0 of `placement` (nothing for [`Placement::OS`]),
    /// saving its mask.
    pub fn caller(placement: Placement) -> anyhow::Result<Pinned> {
        if placement.is_os() {
            return Ok(Pinned { restore: None });
        }
        let restore = os::current()?;
        FAILED_CPU.store(usize::MAX, Ordering::SeqCst);
        placement.on_start(0);
        Ok(Pinned {
            restore: Some(restore),
        })
    }

    /// Restores the calling thread's mask, and fails if any thread of the run could not pin
    /// itself.
    pub fn finish(mut self) -> anyhow::Result<()> {
        self.restore()?;
        match FAILED_CPU.swap(usize::MAX, Ordering::SeqCst) {
            usize::MAX => Ok(()),
            cpu => bail!("the operating system refused to pin a thread of the run to CPU {cpu}"),
        }
    }

    /// Restores the saved mask; kept (for `Drop` to try again) if that fails.
    fn restore(&mut self) -> anyhow::Result<()> {
        if let Some(mask) = &self.restore {
            os::set_current(mask)?;
            self.restore = None;
        }
        Ok(())
    }
}

impl Drop for Pinned {
    fn drop(&mut self) {
        let _ = self.restore();
    }
}

#[cfg(target_os = "linux")]
mod os {
    use anyhow::Context;
    use nix::sched::{CpuSet, sched_getaffinity, sched_setaffinity};
    use nix::unistd::Pid;

    use crate::topology::Pin;

    /// A thread's affinity mask.
    pub type Mask = CpuSet;

    /// The calling thread's mask.
    pub fn current() -> anyhow::Result<Mask> {
        sched_getaffinity(Pid::from_raw(0)).context("cannot read this thread's CPU affinity")
    }

    /// Sets the calling thread's mask.
    pub fn set_current(mask: &Mask) -> anyhow::Result<()> {
        sched_setaffinity(Pid::from_raw(0), mask)
            .context("cannot restore this thread's CPU affinity")
    }

    /// Pins the calling thread to `cpu`.
    pub fn pin_current(cpu: usize) -> nix::Result<()> {
        let mut set = CpuSet::new();
        set.set(cpu)?;
        sched_setaffinity(Pid::from_raw(0), &set)
    }

    /// Moves the calling thread onto every CPU of `order` in turn, then back: an error names
    /// the first CPU the operating system refuses.
    pub fn check(pin: Pin, order: &[usize]) -> anyhow::Result<()> {
        let saved = current()?;
        let refused = order
            .iter()
            .find_map(|&cpu| pin_current(cpu).err().map(|e| (cpu, e)));
        set_current(&saved)?;
        if let Some((cpu, e)) = refused {
            anyhow::bail!(
                "--pin {pin}: the operating system refused to run a thread on CPU {cpu} ({e})"
            );
        }
        Ok(())
    }
}

#[cfg(not(target_os = "linux"))]
mod os {
    use crate::topology::Pin;

    /// No mask outside Linux.
    pub type Mask = ();

    pub fn current() -> anyhow::Result<Mask> {
        Ok(())
    }

    pub fn set_current(_: &Mask) -> anyhow::Result<()> {
        Ok(())
    }

    pub fn pin_current(_: usize) -> Result<(), ()> {
        Err(())
    }

    pub fn check(pin: Pin, _: &[usize]) -> anyhow::Result<()> {
        anyhow::bail!("--pin {pin}: pinning threads is implemented on Linux only")
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    #[test]
    fn a_cpu_the_operating_system_refuses_is_an_error_naming_it_and_the_thread_keeps_its_mask() {
        let before = os::current().unwrap();
        let err = os::check(Pin::Spread, &[1023]).unwrap_err().to_string();
        assert!(
            err.contains("--pin spread") && err.contains("CPU 1023"),
            "{err}"
        );
        assert_eq!(os::current().unwrap(), before);
    }

    #[test]
    fn a_pinned_caller_gets_its_own_mask_back_after_the_run() {
        let before = os::current().unwrap();
        for pin in [Pin::Compact, Pin::Spread] {
            let placement = placement(pin).unwrap();
            assert!(!placement.is_os());
            let pinned = Pinned::caller(placement).unwrap();
            let during = os::current().unwrap();
            let first = machine_topology().order(pin).unwrap()[0];
            assert!(during.is_set(first).unwrap());
            let count = (0..CpuCount::get()).filter(|&c| during.is_set(c).unwrap_or(false));
            assert_eq!(count.count(), 1, "{pin}: pinned to one CPU");
            pinned.finish().unwrap();
            assert_eq!(os::current().unwrap(), before, "{pin}");
        }
        assert!(placement(Pin::None).unwrap().is_os());
    }

    /// The CPUs a mask can name.
    struct CpuCount;

    impl CpuCount {
        fn get() -> usize {
            nix::sched::CpuSet::count()
        }
    }
}
