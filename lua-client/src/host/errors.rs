//! Errors as scripts see them. An error a Rust function of the API returns reaches Lua as an
//! mlua error object (userdata), on which `"x" .. err` and `string.find(err, ...)` throw.
//! Scripts expect what `error("message")` gives: the string `"chunk:line: message"`. So
//! [`install`] wraps `pcall`, `xpcall` (the handler's argument) and `coroutine.resume`: an
//! error object they catch becomes that string, the position being the script line that
//! called into the API; every other error value passes unchanged.

use mlua::{Error, Lua, Value};

/// The wrappers, run once with the converter; they replace the globals they wrap.
const WRAPPERS: &str = r#"
local message = ...
local raw_pcall, raw_xpcall, raw_resume = pcall, xpcall, coroutine.resume
local function caught(ok, ...)
	if ok then
		return true, ...
	end
	return false, message((...))
end
function pcall(f, ...)
	return caught(raw_pcall(f, ...))
end
function xpcall(f, handler, ...)
	if type(handler) ~= "function" then
		return raw_xpcall(f, handler, ...)
	end
	return raw_xpcall(f, function(e)
		return handler(message(e))
	end, ...)
end
function coroutine.resume(co, ...)
	return caught(raw_resume(co, ...))
end
"#;

/// Installs the wrappers in `lua` (before it is sandboxed: they replace builtins).
pub fn install(lua: &Lua) -> mlua::Result<()> {
    let message = lua.create_function(|lua, v: Value| match v {
        Value::Error(e) => Ok(Value::String(lua.create_string(script_message(&e))?)),
        other => Ok(other),
    })?;
    lua.load(WRAPPERS).set_name("=[errors]").call(message)
}

/// `"chunk:line: message"` for an error a Rust function raised: the message of its cause,
/// prefixed by the script position that made the call.
pub fn script_message(e: &Error) -> String {
    let mut cause = e;
    let mut position = None;
    while let Error::CallbackError {
        traceback,
        cause: inner,
    } = cause
    {
        // The outermost callback is the one the script called.
        if position.is_none() {
            position = caller(traceback);
        }
        cause = inner;
    }
    let text = match (cause, colon_hint(cause)) {
        (_, Some(hint)) => hint,
        (Error::RuntimeError(m) | Error::MemoryError(m), None) => m.clone(),
        (other, None) => other.to_string(),
    };
    // A Lua error that went through Rust carries its own traceback: the position says where.
    let text = match text.find("\nstack traceback:") {
        Some(i) => text[..i].to_string(),
        None => text,
    };
    format!("{}{text}", position.unwrap_or_default())
}

/// What to say instead of mlua's "bad argument `self`" when a method was called with `.`
/// (`obj.Method()`, so `self` is missing or another value).
pub fn colon_hint(e: &Error) -> Option<String> {
    let mut cause = e;
    while let Error::CallbackError { cause: inner, .. } = cause {
        cause = inner;
    }
    match cause {
        Error::BadArgument {
            to: Some(to),
            pos: 1,
            name: Some(name),
            ..
        } if name == "self" => {
            let (owner, method) = to.rsplit_once('.').unwrap_or(("value", to.as_str()));
            Some(format!(
                "{owner}.{method} is a method: call it with a colon, x:{method}(...), not \
                 x.{method}(...)"
            ))
        }
        _ => None,
    }
}

/// `"chunk:line: "` of the first script frame in a traceback mlua recorded where a Rust
/// function failed. Skipped: C functions (`[C]`), the host's own chunks (named `[...]`) and
/// mlua's helpers (`__mlua...`).
fn caller(traceback: &str) -> Option<String> {
    traceback.lines().skip(1).find_map(|line| {
        let (at, _) = line.trim_start().split_once(": in ")?;
        if at.starts_with('[') || at.starts_with("__mlua") {
            return None;
        }
        let (_, n) = at.rsplit_once(':')?;
        n.parse::<u32>().ok()?;
        Some(format!("{at}: "))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caller_is_the_first_script_frame() {
        let tb =
            "stack traceback:\n\t[C]: in ?\n\t__mlua_index:31: in function <__mlua_index:15>\n\
                  \t[wait]:2: in function 'wait'\n\tscript.luau:12: in function <script.luau:10>\n\
                  \t[C]: in function 'pcall'";
        assert_eq!(caller(tb).as_deref(), Some("script.luau:12: "));
        assert_eq!(caller("stack traceback:\n\t[C]: in ?"), None);
    }

    #[test]
    // mlua's CallbackError holds its cause in an Arc whatever the cause.
    #[allow(clippy::arc_with_non_send_sync)]
    fn message_is_the_root_cause_with_the_callers_position() {
        let e = Error::CallbackError {
            traceback: "stack traceback:\n\t[C]: in ?\n\tx.luau:3: in function <x.luau:1>".into(),
            cause: std::sync::Arc::new(Error::runtime("bad\nstack traceback:\n\t[C]: in ?")),
        };
        assert_eq!(script_message(&e), "x.luau:3: bad");
    }
}
