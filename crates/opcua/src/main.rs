//! `motion-opcua`: the supervisor on the plant network (see `lib.rs` and
//! the README's "On the plant network").

use clap::Parser;
use motion_opcua::cli::{Cli, Command};
use std::io::{BufRead, Read};

fn main() {
    // Nothing we create (key, trust list) is for other users.
    // SAFETY: umask has no failure mode.
    unsafe {
        libc::umask(0o077);
    }
    motion_opcua::logging::init();
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            std::process::exit(if e.use_stderr() { 2 } else { 0 });
        }
    };
    // The hash does not need the config (a user being added may not
    // have a valid password_hash yet).
    if let Some(Command::HashPassword) = cli.command {
        if let Err(e) = hash_password() {
            log::error!("{e}");
            std::process::exit(1);
        }
        return;
    }
    let (mut machine, cfg) = match motion_config::opcua::load(&cli.config) {
        Ok(x) => x,
        Err(problems) => {
            for p in problems {
                eprintln!("motion-opcua: {}: {p}", cli.config.display());
            }
            std::process::exit(2);
        }
    };
    if let Some(d) = cli.runtime_dir {
        if let Err(e) = motion_config::args::runtime_dir(&d.to_string_lossy()) {
            eprintln!("motion-opcua: --runtime-dir: {e}");
            std::process::exit(2);
        }
        machine.supervisor.runtime_dir = Some(d);
    }
    let r = match cli.command {
        Some(Command::HashPassword) => Ok(()),
        Some(Command::Trust { cert }) => trust(&cfg.pki_dir, &cert),
        None => serve(machine, cfg, cli.config.clone()),
    };
    if let Err(e) = r {
        log::error!("{e}");
        std::process::exit(1);
    }
}

/// `trust`: what is trusted (subject, fingerprints), then where it went.
fn trust(pki: &std::path::Path, cert: &std::path::Path) -> Result<(), String> {
    let what = motion_opcua::pki::describe(&motion_opcua::pki::read_cert(cert)?)?;
    let to = motion_opcua::pki::trust(pki, cert)?;
    println!("{what}");
    println!(
        "trusted: {} (effective for the next connection; delete it to revoke)",
        to.display()
    );
    Ok(())
}

/// `hash-password`: from a pipe, everything up to EOF; from a terminal,
/// one line typed with echo off (the password is never shown).
fn hash_password() -> Result<(), String> {
    let mut text = String::new();
    let limit = motion_opcua::password::MAX_PASSWORD as u64 + 2;
    let read = match NoEcho::on_tty() {
        Some(_quiet) => {
            eprint!("password (not shown): ");
            std::io::stdin().lock().take(limit).read_line(&mut text)
        }
        None => std::io::stdin().take(limit).read_to_string(&mut text),
    };
    read.map_err(|e| format!("reading the password from stdin: {e}"))?;
    let pw = text.strip_suffix('\n').unwrap_or(&text);
    let pw = pw.strip_suffix('\r').unwrap_or(pw);
    let h = motion_opcua::password::hash(pw)?;
    println!("{h}");
    Ok(())
}

fn serve(
    machine: motion_config::MachineConfig,
    cfg: motion_config::opcua::OpcuaConfig,
    config: std::path::PathBuf,
) -> Result<(), String> {
    // Like motionctl and HMIs: never on the cycle's CPU (threads made
    // from here on, tokio's included, inherit the mask).
    match motion_rt::keep_off_cpu(machine.supervisor.cpu) {
        Ok(cpus) => log::info!(
            "kept off the cycle's cpu {} (on {cpus:?})",
            machine.supervisor.cpu
        ),
        Err(w) => log::warn!("{w}"),
    }
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .thread_name("motion-opcua")
        .enable_all()
        .build()
        .map_err(|e| format!("tokio runtime: {e}"))?;
    rt.block_on(motion_opcua::server::serve(machine, cfg, config))
}

/// Terminal echo switched off while it lives (stdin a terminal only).
struct NoEcho(libc::termios);

impl NoEcho {
    fn on_tty() -> Option<NoEcho> {
        // SAFETY: isatty/tcgetattr/tcsetattr on fd 0 with a termios we own.
        unsafe {
            if libc::isatty(0) != 1 {
                return None;
            }
            let mut t: libc::termios = std::mem::zeroed();
            if libc::tcgetattr(0, &mut t) != 0 {
                return None;
            }
            let saved = t;
            t.c_lflag &= !libc::ECHO;
            t.c_lflag |= libc::ECHONL;
            (libc::tcsetattr(0, libc::TCSANOW, &t) == 0).then_some(NoEcho(saved))
        }
    }
}

impl Drop for NoEcho {
    fn drop(&mut self) {
        // SAFETY: restores the settings read in `on_tty`.
        unsafe {
            libc::tcsetattr(0, libc::TCSANOW, &self.0);
        }
    }
}
