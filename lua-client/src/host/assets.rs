//! Where a script may load map and prop files from (`LoadMap`, `LoadProp`): the asset roots.
//! A path is resolved (symlinks and `..` included) and must lie under one of them; anything
//! else (outside, missing, unreadable) is refused with one message that names the path as
//! given and nothing else, so a script cannot probe which files exist on the host.
//!
//! `physics-lua` sets the roots from `--asset-root` (default: the script's directory and the
//! current directory); a host that sets none allows the current directory.

use std::path::{Path, PathBuf};

use mlua::Lua;

/// The directories scripts may load assets from (canonical paths).
#[derive(Debug, Clone, Default)]
pub struct AssetRoots {
    roots: Vec<PathBuf>,
}

impl AssetRoots {
    /// The roots `dirs`; directories that do not exist are left out (none can lie under
    /// them).
    pub fn new(dirs: impl IntoIterator<Item = PathBuf>) -> AssetRoots {
        let mut roots: Vec<PathBuf> = dirs
            .into_iter()
            .filter_map(|d| d.canonicalize().ok())
            .collect();
        roots.sort();
        roots.dedup();
        AssetRoots { roots }
    }

    /// The roots, canonical.
    pub fn roots(&self) -> &[PathBuf] {
        &self.roots
    }

    /// Sets the roots of the scripts of `lua`.
    pub fn install(self, lua: &Lua) {
        lua.set_app_data(self);
    }

    /// `path` resolved, when it is a readable file under a root; otherwise the one refusal
    /// for `what`.
    pub fn resolve(&self, what: &str, path: &str) -> mlua::Result<PathBuf> {
        let refused = || {
            mlua::Error::runtime(format!(
                "{what}: cannot load {path:?}: not a readable file under the asset roots \
                 (physics-lua --asset-root)"
            ))
        };
        let resolved = Path::new(path).canonicalize().map_err(|_| refused())?;
        if !self.roots.iter().any(|root| resolved.starts_with(root)) {
            return Err(refused());
        }
        match std::fs::File::open(&resolved).and_then(|f| f.metadata()) {
            Ok(m) if m.is_file() => Ok(resolved),
            _ => Err(refused()),
        }
    }
}

impl AssetRoots {
    /// Where a file `path` may be written: its directory must lie under a root (the file
    /// itself may not exist yet) and `path` must not name a directory; otherwise one
    /// refusal for `what`.
    pub fn resolve_for_write(&self, what: &str, path: &str) -> mlua::Result<PathBuf> {
        let refused = || {
            mlua::Error::runtime(format!(
                "{what}: cannot write {path:?}: not a file in a directory under the asset \
                 roots (physics-lua --asset-root)"
            ))
        };
        let p = Path::new(path);
        let name = p.file_name().ok_or_else(refused)?;
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let dir = dir.canonicalize().map_err(|_| refused())?;
        if !self.roots.iter().any(|root| dir.starts_with(root)) {
            return Err(refused());
        }
        let target = dir.join(name);
        if target.is_dir() {
            return Err(refused());
        }
        Ok(target)
    }
}

/// Where `lua`'s scripts may write the file `path` (see [`AssetRoots::resolve_for_write`]).
pub fn resolve_for_write(lua: &Lua, what: &str, path: &str) -> mlua::Result<PathBuf> {
    match lua.app_data_ref::<AssetRoots>() {
        Some(roots) => roots.resolve_for_write(what, path),
        None => AssetRoots::new(std::env::current_dir().ok()).resolve_for_write(what, path),
    }
}

/// `path` resolved against the roots of `lua` (the current directory when the host set
/// none), or the refusal for `what`.
pub fn resolve(lua: &Lua, what: &str, path: &str) -> mlua::Result<PathBuf> {
    match lua.app_data_ref::<AssetRoots>() {
        Some(roots) => roots.resolve(what, path),
        None => AssetRoots::new(std::env::current_dir().ok()).resolve(what, path),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outside_missing_and_inside_paths() {
        let dir = std::env::temp_dir().join(format!("asset-roots-{}", std::process::id()));
        let inside = dir.join("in");
        std::fs::create_dir_all(&inside).unwrap();
        std::fs::write(inside.join("a.glb"), b"x").unwrap();
        std::fs::write(dir.join("secret.glb"), b"x").unwrap();
        let roots = AssetRoots::new([inside.clone(), dir.join("missing-dir")]);
        assert_eq!(roots.roots().len(), 1);
        let ok = inside.join("a.glb");
        assert!(roots.resolve("Load", ok.to_str().unwrap()).is_ok());
        // Outside (also through ..), missing and a directory: one message, naming the path.
        let escape = inside.join("../secret.glb");
        let missing = inside.join("nope.glb");
        let messages: Vec<String> = [escape.clone(), missing.clone(), inside.clone()]
            .iter()
            .map(|p| {
                let p = p.to_str().unwrap();
                roots
                    .resolve("Load", p)
                    .unwrap_err()
                    .to_string()
                    .replace(p, "PATH")
            })
            .collect();
        assert!(messages.iter().all(|m| *m == messages[0]), "{messages:?}");
        assert!(messages[0].contains("asset roots"), "{}", messages[0]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
