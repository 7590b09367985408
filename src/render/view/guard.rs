//! What the editor's server trusts, checked before it carries out a request (the model is
//! Jupyter's server):
//!
//! - [`Token`]: a secret drawn from the operating system's random source for each run, printed in
//!   the URL; every request but the page's own files must carry it (`Authorization: token T`).
//!   It is compared in constant time, so answers' timing tells nothing of it.
//! - [`Local`]: the `Host` a request names must be this server's loopback address and port, so a
//!   page whose name was made to point at 127.0.0.1 (DNS rebinding) is refused; an `Origin`, when
//!   given, must be the server's own, so another site's page cannot make it act.
//! - [`Folder`]: what the page writes (part files, meshes, slices) stays inside one folder, with
//!   `..` and symbolic links resolved by the operating system before the check.

use crate::error::{Error, Result};
use std::path::{Component, Path, PathBuf};

/// Random bytes in a token: 256 bits.
const TOKEN_BYTES: usize = 32;

/// The secret of one run of the server.
pub struct Token(String);

impl Token {
    /// A new token from the operating system's random source.
    pub fn new() -> Result<Token> {
        let mut bytes = [0u8; TOKEN_BYTES];
        getrandom::fill(&mut bytes).map_err(|e| {
            Error::invalid(format!("no random numbers for the editor's token: {e}"))
        })?;
        Ok(Token(bytes.iter().map(|b| format!("{b:02x}")).collect()))
    }

    /// The token as it is printed and sent: hexadecimal digits.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// Whether an `Authorization` header's value is `token T` with this token.
    pub fn admits(&self, authorization: Option<&str>) -> bool {
        let Some(value) = authorization else {
            return false;
        };
        let value = value.trim();
        let Some((scheme, given)) = value.split_once(' ') else {
            return false;
        };
        scheme.eq_ignore_ascii_case("token")
            && constant_time_eq::constant_time_eq(given.trim().as_bytes(), self.0.as_bytes())
    }
}

/// The loopback names a client may give this server by: `127.0.0.1`, `localhost` and `[::1]`,
/// each with the server's port.
pub struct Local {
    port: u16,
}

impl Local {
    /// The server listening on `port`.
    pub fn new(port: u16) -> Local {
        Local { port }
    }

    /// `host:port` for each loopback name (the bare names too on port 80, as browsers send).
    fn authorities(&self) -> Vec<String> {
        let mut v: Vec<String> = ["127.0.0.1", "localhost", "[::1]"]
            .iter()
            .map(|h| format!("{h}:{}", self.port))
            .collect();
        if self.port == 80 {
            v.extend(["127.0.0.1", "localhost", "[::1]"].map(String::from));
        }
        v
    }

    /// Whether a `Host` header's value names this server.
    pub fn host_ok(&self, host: Option<&str>) -> bool {
        host.is_some_and(|h| {
            let h = h.trim();
            self.authorities().iter().any(|a| a.eq_ignore_ascii_case(h))
        })
    }

    /// Whether an `Origin` header's value, if any, is this server's own (its page).
    pub fn origin_ok(&self, origin: Option<&str>) -> bool {
        let Some(origin) = origin else { return true };
        let origin = origin.trim();
        self.authorities()
            .iter()
            .any(|a| origin.eq_ignore_ascii_case(&format!("http://{a}")))
    }
}

/// A name the page gave that lies outside the folder the editor writes in.
#[derive(Debug)]
pub struct Outside(pub String);

impl std::fmt::Display for Outside {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Outside {}

/// The folder the editor writes in.
pub struct Folder {
    root: PathBuf,
}

impl Folder {
    /// The folder `dir` (which must exist), by its real path.
    pub fn new(dir: &Path) -> Result<Folder> {
        let root = dir.canonicalize().map_err(|e| Error::io(dir, e))?;
        if !root.is_dir() {
            return Err(Error::invalid(format!("{}: not a folder", dir.display())));
        }
        Ok(Folder { root })
    }

    /// The folder's real path.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Where the name `name` writes: relative names are inside the folder; any name is refused
    /// when, with `..` and symbolic links resolved, it is not strictly inside it. The answer is
    /// the real path, the one to write, so that nothing is resolved again later.
    pub fn resolve(&self, name: &str) -> std::result::Result<PathBuf, Outside> {
        let outside = || {
            Outside(format!(
                "{name}: outside the folder this editor writes in ({}; `latvox view --out-dir` names another)",
                self.root.display()
            ))
        };
        let given = Path::new(name);
        let full = if given.is_absolute() {
            given.to_path_buf()
        } else {
            self.root.join(given)
        };
        // The deepest part of the path that exists (a link counts, even a broken one): the
        // operating system resolves its links and `..`; a broken link leads nowhere, refused.
        let mut existing = full.as_path();
        while std::fs::symlink_metadata(existing).is_err() {
            existing = existing.parent().ok_or_else(outside)?;
        }
        let mut real = existing.canonicalize().map_err(|_| outside())?;
        let rest = full.strip_prefix(existing).map_err(|_| outside())?;
        // What does not exist yet has no links; a `..` in it could climb out of a link's target.
        for c in rest.components() {
            match c {
                Component::Normal(part) => real.push(part),
                _ => return Err(outside()),
            }
        }
        if real == self.root || !real.starts_with(&self.root) {
            return Err(outside());
        }
        Ok(real)
    }

    /// Whether `path` lies inside the folder.
    pub fn holds(&self, path: &Path) -> bool {
        path.to_str().is_some_and(|p| self.resolve(p).is_ok())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_are_long_random_and_checked_whole() {
        let (a, b) = (Token::new().unwrap(), Token::new().unwrap());
        assert_eq!(a.as_str().len(), 2 * TOKEN_BYTES);
        assert_ne!(a.as_str(), b.as_str());
        let good = format!("token {}", a.as_str());
        assert!(a.admits(Some(&good)));
        assert!(a.admits(Some(&format!("Token  {} ", a.as_str()))));
        for bad in [
            String::new(),
            a.as_str().to_string(),
            format!("Bearer {}", a.as_str()),
            format!("token {}", b.as_str()),
            format!("token {}", &a.as_str()[1..]),
            format!("token {}0", a.as_str()),
        ] {
            assert!(!a.admits(Some(&bad)), "{bad}");
        }
        assert!(!a.admits(None));
    }

    #[test]
    fn only_loopback_names_with_the_port_are_served() {
        let l = Local::new(8080);
        for ok in [
            "127.0.0.1:8080",
            "localhost:8080",
            "LOCALHOST:8080",
            "[::1]:8080",
        ] {
            assert!(l.host_ok(Some(ok)), "{ok}");
        }
        for bad in [
            "evil.example:8080",
            "127.0.0.1",
            "localhost:80",
            "127.0.0.1:8081",
            "",
        ] {
            assert!(!l.host_ok(Some(bad)), "{bad}");
        }
        assert!(!l.host_ok(None));
        assert!(l.origin_ok(None));
        assert!(l.origin_ok(Some("http://localhost:8080")));
        for bad in [
            "http://evil.example",
            "null",
            "https://127.0.0.1:8080",
            "http://127.0.0.1",
        ] {
            assert!(!l.origin_ok(Some(bad)), "{bad}");
        }
    }

    #[test]
    fn names_resolve_inside_the_folder_or_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let root = d.path().join("part");
        let out = d.path().join("elsewhere");
        std::fs::create_dir_all(root.join("sub")).unwrap();
        std::fs::create_dir_all(&out).unwrap();
        let f = Folder::new(&root).unwrap();
        let real = root.canonicalize().unwrap();
        assert_eq!(f.resolve("a.stl").unwrap(), real.join("a.stl"));
        assert_eq!(f.resolve("sub/../b.stl").unwrap(), real.join("b.stl"));
        assert_eq!(f.resolve("new/c.stl").unwrap(), real.join("new/c.stl"));
        let abs = real.join("sub/d.toml");
        assert_eq!(f.resolve(abs.to_str().unwrap()).unwrap(), abs);
        let mut refused = vec![
            "../x.toml".to_string(),
            "new/../../x.toml".into(),
            ".".into(),
            "sub/..".into(),
            out.join("x.stl").display().to_string(),
        ];
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&out, root.join("link")).unwrap();
            std::os::unix::fs::symlink(out.join("t.toml"), root.join("file.toml")).unwrap();
            std::os::unix::fs::symlink(root.join("gone"), root.join("broken.toml")).unwrap();
            refused.extend(["link/x.toml", "link", "file.toml", "broken.toml"].map(String::from));
        }
        for name in refused {
            assert!(f.resolve(&name).is_err(), "{name} was let through");
        }
    }
}
