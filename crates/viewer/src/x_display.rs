//! An X display for running the viewer's window where no desktop is: the
//! session's `DISPLAY`, else an `Xvfb` started here and stopped on drop.
//! `strata soak` and the window tests share it.

use anyhow::Context;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};

/// A display name to put in `DISPLAY`, and the Xvfb behind it if we started one.
pub struct XDisplay {
    /// The value for `DISPLAY`, e.g. `:1`.
    pub name: String,
    xvfb: Option<Child>,
}

impl XDisplay {
    /// The session's `DISPLAY` when set, else a fresh Xvfb (1024x768x24, no
    /// TCP) on a display number it picks itself.
    pub fn open() -> anyhow::Result<Self> {
        if let Some(name) = std::env::var("DISPLAY").ok().filter(|d| !d.is_empty()) {
            return Ok(Self { name, xvfb: None });
        }
        // -displayfd: Xvfb picks a free display and writes its number when ready.
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1024x768x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .context("no DISPLAY and Xvfb would not start (apt-get install -y xvfb)")?;
        let mut line = String::new();
        let read = child
            .stdout
            .take()
            .context("Xvfb's stdout")
            .and_then(|out| {
                BufReader::new(out)
                    .read_line(&mut line)
                    .context("reading Xvfb's display number")
            });
        let number = read.and_then(|_| {
            line.trim()
                .parse::<u32>()
                .with_context(|| format!("Xvfb gave no display number (`{}`)", line.trim()))
        });
        match number {
            Ok(n) => Ok(Self {
                name: format!(":{n}"),
                xvfb: Some(child),
            }),
            Err(e) => {
                let _ = child.kill();
                let _ = child.wait();
                Err(e)
            }
        }
    }
}

impl Drop for XDisplay {
    fn drop(&mut self) {
        if let Some(child) = &mut self.xvfb {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}
