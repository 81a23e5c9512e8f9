//! Signals: `:Connect(fn)` returns a connection with `:Disconnect()`. Each handler runs in a
//! coroutine of its own, so it may `wait`.

use std::cell::{Cell, RefCell};
use std::rc::{Rc, Weak};

use mlua::{
    Function, Lua, MetaMethod, MultiValue, UserData, UserDataFields, UserDataMethods, Value,
};

use super::scheduler;
use crate::values::expected;

struct Slot {
    id: u64,
    handler: Function,
    once: bool,
}

/// What a signal tells when its number of handlers changes.
type ListenerHook = Box<dyn Fn(usize)>;

/// The connections of a signal, shared by its clones.
#[derive(Default)]
pub struct SignalInner {
    name: String,
    slots: RefCell<Vec<Slot>>,
    next_id: Cell<u64>,
    /// Told the number of handlers whenever it changes (a part's Touched asks the daemon
    /// for contact events only while someone listens).
    on_listeners: RefCell<Option<ListenerHook>>,
}

impl SignalInner {
    fn listeners_changed(&self) {
        let n = self.slots.borrow().len();
        if let Some(f) = self.on_listeners.borrow().as_ref() {
            f(n);
        }
    }
}

/// A signal; clones share the same connections.
#[derive(Clone)]
pub struct Signal(pub Rc<SignalInner>);

impl Signal {
    /// A signal with no connections; `name` is what `tostring` shows.
    pub fn new(name: impl Into<String>) -> Signal {
        Signal(Rc::new(SignalInner {
            name: name.into(),
            ..Default::default()
        }))
    }

    /// How many handlers are connected: the probe that lets per-tick work stop at zero.
    pub fn listeners(&self) -> usize {
        self.0.slots.borrow().len()
    }

    /// Calls `f` with the number of handlers each time it changes.
    pub fn on_listeners(&self, f: impl Fn(usize) + 'static) {
        *self.0.on_listeners.borrow_mut() = Some(Box::new(f));
    }

    /// The script's value of this signal: the same userdata on every read while the script
    /// holds it (`part.Touched == part.Touched`, `rawequal`), through the identity registry.
    pub fn userdata(&self, lua: &Lua) -> mlua::Result<mlua::AnyUserData> {
        super::identity::userdata(
            lua,
            Rc::as_ptr(&self.0).cast(),
            super::identity::tag::SIGNAL,
            || self.clone(),
        )
    }

    /// Drops every connection.
    pub fn disconnect_all(&self) {
        let had = !self.0.slots.borrow().is_empty();
        self.0.slots.borrow_mut().clear();
        if had {
            self.0.listeners_changed();
        }
    }

    fn connect(&self, handler: Function, once: bool) -> Connection {
        let id = self.0.next_id.get();
        self.0.next_id.set(id + 1);
        self.0.slots.borrow_mut().push(Slot { id, handler, once });
        self.0.listeners_changed();
        Connection {
            signal: Rc::downgrade(&self.0),
            id,
        }
    }

    /// Runs every handler connected now with `args`. Handlers connected while firing wait for
    /// the next fire; one-shot handlers are removed before they run.
    pub fn fire(&self, lua: &Lua, args: MultiValue) -> mlua::Result<()> {
        let (handlers, removed): (Vec<Function>, bool) = {
            let mut slots = self.0.slots.borrow_mut();
            let handlers = slots.iter().map(|s| s.handler.clone()).collect();
            let before = slots.len();
            slots.retain(|s| !s.once);
            (handlers, slots.len() != before)
        };
        if removed {
            self.0.listeners_changed();
        }
        for handler in handlers {
            scheduler::spawn_handler(lua, &self.0.name, handler, args.clone())?;
        }
        Ok(())
    }
}

fn handler_arg(what: &str, v: Value) -> mlua::Result<Function> {
    match v {
        Value::Function(f) => Ok(f),
        other => Err(expected(what, "a function", &other)),
    }
}

impl UserData for Signal {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("Connect", |_, s, f: Value| {
            Ok(s.connect(handler_arg("Signal:Connect", f)?, false))
        });
        methods.add_method("Once", |_, s, f: Value| {
            Ok(s.connect(handler_arg("Signal:Once", f)?, true))
        });
        methods.add_meta_method(MetaMethod::ToString, |_, s, ()| {
            Ok(format!("Signal {}", s.0.name))
        });
        // Two values of one signal are equal (one value per signal is handed out anyway).
        methods.add_meta_method(MetaMethod::Eq, |_, s, other: Value| {
            Ok(match other {
                Value::UserData(ud) => ud.borrow::<Signal>().is_ok_and(|o| Rc::ptr_eq(&o.0, &s.0)),
                _ => false,
            })
        });
    }
}

/// What `:Connect` returns.
pub struct Connection {
    signal: Weak<SignalInner>,
    id: u64,
}

impl Connection {
    fn connected(&self) -> bool {
        self.signal
            .upgrade()
            .is_some_and(|s| s.slots.borrow().iter().any(|slot| slot.id == self.id))
    }
}

impl UserData for Connection {
    fn add_fields<F: UserDataFields<Self>>(fields: &mut F) {
        fields.add_field_method_get("Connected", |_, c| Ok(c.connected()));
    }

    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("Disconnect", |_, c, ()| {
            if let Some(signal) = c.signal.upgrade() {
                let before = signal.slots.borrow().len();
                signal.slots.borrow_mut().retain(|slot| slot.id != c.id);
                if signal.slots.borrow().len() != before {
                    signal.listeners_changed();
                }
            }
            Ok(())
        });
    }
}
