//! Frames, `wait` and coroutines. Every script thread and signal handler runs as a coroutine;
//! `wait(s)` yields it with a marker and the scheduler resumes it in the first frame at least
//! `s` seconds later, returning the time actually waited.

use std::cell::RefCell;
use std::ffi::c_void;
use std::rc::{Rc, Weak};
use std::time::Instant;

use mlua::{Function, LightUserData, Lua, MultiValue, Thread, ThreadStatus, Value};

use super::watchdog::Watchdog;
use super::watched::Watched;
use crate::values::{expected, number};

static WAIT_MARK: u8 = 0;

fn wait_mark() -> LightUserData {
    LightUserData(&WAIT_MARK as *const u8 as *mut c_void)
}

struct Waiting {
    wake_at: f64,
    since: f64,
    thread: Thread,
    /// The signal handler this thread runs (`None`: a script thread).
    handler: Option<Rc<Handler>>,
}

/// A signal handler's thread: its error is reported and contained, as on Roblox.
pub(crate) struct Handler {
    /// What fired it ("Heart", "Touched").
    signal: String,
    /// The handler function (for the line that defines it).
    function: Function,
}

/// The frame loop's state: pending waits and what is watched each frame.
pub struct Scheduler {
    started: Instant,
    waiting: RefCell<Vec<Waiting>>,
    /// Values with per-frame change signals (simulated parts' CFrame); probed each frame
    /// for listeners.
    watched: RefCell<Vec<Weak<dyn Watched>>>,
    /// Stops scripts that run too long (see `watchdog`).
    pub watchdog: Rc<Watchdog>,
}

impl Scheduler {
    /// A scheduler with nothing pending; its clock starts now.
    pub fn new() -> Scheduler {
        Scheduler {
            started: Instant::now(),
            waiting: RefCell::default(),
            watched: RefCell::default(),
            watchdog: Rc::new(Watchdog::new()),
        }
    }

    fn clock(&self) -> f64 {
        self.started.elapsed().as_secs_f64()
    }

    /// Probes `watched` every frame until it is dropped.
    pub fn watch(&self, watched: Rc<dyn Watched>) {
        self.watched.borrow_mut().push(Rc::downgrade(&watched));
    }

    /// How many script threads wait to be resumed.
    pub fn pending_waits(&self) -> usize {
        self.waiting.borrow().len()
    }

    /// Seconds until the earliest pending `wait` is due (None without waits).
    pub fn next_wake_in(&self) -> Option<f64> {
        let now = self.clock();
        self.waiting
            .borrow()
            .iter()
            .map(|w| (w.wake_at - now).max(0.0))
            .min_by(f64::total_cmp)
    }

    /// Whether any per-tick change signal has a listener.
    pub fn change_listeners(&self) -> bool {
        self.watched
            .borrow()
            .iter()
            .filter_map(Weak::upgrade)
            .any(|w| w.listeners() > 0 && w.keeps_running())
    }

    /// One frame's scheduling. Physics results come first: the change signals of simulated
    /// parts with listeners fire when their pose moved; then due waits resume, so scripts
    /// see this frame's poses (the host fires `Heart` next).
    pub fn frame(&self, lua: &Lua) -> mlua::Result<()> {
        let watched: Vec<Rc<dyn Watched>> = {
            let mut watched = self.watched.borrow_mut();
            watched.retain(|w| w.strong_count() > 0);
            watched.iter().filter_map(Weak::upgrade).collect()
        };
        for w in watched {
            // The empty-listener probe: what nobody listens to costs one length check.
            if w.listeners() > 0 {
                w.fire_if_changed(lua)?;
            }
        }
        let now = self.clock();
        let due: Vec<Waiting> = {
            let mut waiting = self.waiting.borrow_mut();
            let (due, rest) = std::mem::take(&mut *waiting)
                .into_iter()
                .partition(|w| w.wake_at <= now);
            *waiting = rest;
            due
        };
        for w in due {
            let handler = w.handler.clone();
            let resumed = resume(
                self,
                w.thread.clone(),
                (now - w.since).into_lua_multi_value(),
                handler.clone(),
            );
            contain(lua, self, resumed, &w.thread, handler.as_deref())?;
        }
        Ok(())
    }
}

trait IntoMulti {
    fn into_lua_multi_value(self) -> MultiValue;
}

impl IntoMulti for Value {
    fn into_lua_multi_value(self) -> MultiValue {
        MultiValue::from_iter([self])
    }
}

impl IntoMulti for f64 {
    fn into_lua_multi_value(self) -> MultiValue {
        Value::Number(self).into_lua_multi_value()
    }
}

/// The scheduler `install` registered in `lua`.
pub fn scheduler(lua: &Lua) -> Rc<Scheduler> {
    lua.app_data_ref::<Rc<Scheduler>>()
        .expect("lua_client::install registers the scheduler")
        .clone()
}

/// Runs `f(args)` as a new coroutine; if it waits, the scheduler resumes it later.
pub fn spawn(lua: &Lua, f: Function, args: MultiValue) -> mlua::Result<()> {
    let thread = lua.create_thread(f)?;
    resume(&scheduler(lua), thread, args, None)
}

/// Runs handler `f(args)` of `signal` as a new coroutine, isolated: an error in it (now or
/// after it waits) is printed with its traceback and the line that defines the handler,
/// and the caller, the other handlers and the script go on. Only a stop of the whole
/// script (the watchdog, memory) goes through.
pub fn spawn_handler(lua: &Lua, signal: &str, f: Function, args: MultiValue) -> mlua::Result<()> {
    let thread = lua.create_thread(f.clone())?;
    let handler = Rc::new(Handler {
        signal: signal.to_string(),
        function: f,
    });
    let sched = scheduler(lua);
    let resumed = resume(&sched, thread.clone(), args, Some(handler.clone()));
    contain(lua, &sched, resumed, &thread, Some(&handler))
}

/// Reports and swallows the error of a handler's thread; passes anything else on.
fn contain(
    lua: &Lua,
    sched: &Scheduler,
    resumed: mlua::Result<()>,
    thread: &Thread,
    handler: Option<&Handler>,
) -> mlua::Result<()> {
    let (Err(e), Some(handler)) = (&resumed, handler) else {
        return resumed;
    };
    if sched.watchdog.stopped().is_some() || matches!(e, mlua::Error::MemoryError(_)) {
        return resumed;
    }
    let info = handler.function.info();
    let defined = match info.short_src {
        Some(src) => format!("{src}:{}", info.line_defined.unwrap_or(0)),
        None => "?".to_string(),
    };
    let message = e.to_string();
    let traceback = if message.contains("stack traceback") {
        message
    } else {
        lua.globals()
            .get::<mlua::Table>("debug")
            .and_then(|d| d.get::<Function>("traceback"))
            .and_then(|tb| tb.call::<String>((thread.clone(), message.clone())))
            .unwrap_or(message)
    };
    eprintln!(
        "error in a {} handler (the function at {defined}); the script goes on:\n{traceback}",
        handler.signal
    );
    Ok(())
}

fn resume(
    sched: &Scheduler,
    thread: Thread,
    args: MultiValue,
    handler: Option<Rc<Handler>>,
) -> mlua::Result<()> {
    let out: MultiValue = {
        let _running = sched.watchdog.running();
        thread.resume(args)?
    };
    if thread.status() != ThreadStatus::Resumable {
        return Ok(());
    }
    // Yielded: by `wait` (marker, seconds) or by a bare coroutine.yield (next frame).
    let delay = match (out.front(), out.get(1)) {
        (Some(Value::LightUserData(m)), Some(s)) if *m == wait_mark() => number(s).unwrap_or(0.0),
        _ => 0.0,
    };
    if delay == f64::INFINITY {
        // `wait(math.huge)`: the thread is never resumed, so nothing keeps it (nor the run).
        return Ok(());
    }
    let now = sched.clock();
    sched.waiting.borrow_mut().push(Waiting {
        wake_at: now + delay,
        since: now,
        thread,
        handler,
    });
    Ok(())
}

/// The global `wait(seconds?)`: a Luau function, since only Luau code can yield here.
pub fn wait_function(lua: &Lua) -> mlua::Result<Function> {
    let check = lua.create_function(|_, s: Value| match s {
        Value::Nil => Ok(0.0),
        v => match number(&v) {
            // math.huge waits forever, as Roblox's task.wait(math.huge) does.
            Some(n) if n >= 0.0 => Ok(n),
            _ => Err(expected(
                "wait",
                "a non-negative number of seconds (or nothing)",
                &v,
            )),
        },
    })?;
    let yield_fn: Function = lua
        .globals()
        .get::<mlua::Table>("coroutine")?
        .get("yield")?;
    lua.load(
        "local mark, check, yield = ...\n\
         return function(seconds) return yield(mark, check(seconds)) end",
    )
    .set_name("=[wait]")
    .call((wait_mark(), check, yield_fn))
}
