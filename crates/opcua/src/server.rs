//! `motion-opcua --config FILE`: the server.
//!
//! Endpoints: one per configured policy, all Sign & Encrypt (a configured
//! `None` policy adds an unsecured endpoint for anonymous readers only),
//! at `[opcua] endpoint` (127.0.0.1:4840 by default). Client certificates
//! must be trusted ([`crate::pki`]); users per [`crate::auth`]. The values
//! come from the bridge thread ([`crate::bridge`]), which joins the daemon
//! like `motionctl`.

use crate::auth::Roles;
use crate::bridge::{self, Handle, Target};
use crate::manager::{Builder, MachineManager};
use crate::values::Publisher;
use crate::{pki, space::NAMESPACE_URI};
use motion_config::opcua::{OpcuaConfig, Policy};
use motion_config::MachineConfig;
use opcua::crypto::SecurityPolicy;
use opcua::server::node_manager::memory::{InMemoryNodeManager, InMemoryNodeManagerBuilder};
use opcua::server::{ServerBuilder, ServerEndpoint, ANONYMOUS_USER_TOKEN_ID};
use opcua::types::MessageSecurityMode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Sampling and publishing as fast as the status service publishes.
pub const MIN_INTERVAL_MS: f64 = 10.0;
/// Values a monitored item may queue (a 10 s publishing interval at 100 Hz).
pub const MAX_QUEUE: usize = 1000;

/// What one client (or many) may hold of the server, so that a hostile or
/// broken one cannot exhaust it: sessions in all (an HMI, a PLC, a SCADA
/// and their engineering tools fit many times over), subscriptions per
/// session, monitored items per subscription (every variable of 16 axes),
/// notification messages a subscription keeps for a client that does not
/// publish (the stack's own 20, stated), and how long an abandoned
/// session lingers (a session silent for this long is closed; with it a
/// jog it started, should its Duration still run).
pub const MAX_SESSIONS: usize = 20;
pub const MAX_SUBSCRIPTIONS_PER_SESSION: usize = 10;
pub const MAX_MONITORED_ITEMS_PER_SUB: usize = 1000;
pub const MAX_QUEUED_NOTIFICATIONS: usize = 20;
pub const MAX_SESSION_TIMEOUT_MS: u64 = 60_000;
/// A connection that sends no Hello within this is dropped.
pub const HELLO_TIMEOUT_S: u32 = 5;

fn stack_policy(p: Policy) -> (SecurityPolicy, MessageSecurityMode) {
    match p {
        Policy::Basic256Sha256 => (
            SecurityPolicy::Basic256Sha256,
            MessageSecurityMode::SignAndEncrypt,
        ),
        Policy::Aes128Sha256RsaOaep => (
            SecurityPolicy::Aes128Sha256RsaOaep,
            MessageSecurityMode::SignAndEncrypt,
        ),
        Policy::Aes256Sha256RsaPss => (
            SecurityPolicy::Aes256Sha256RsaPss,
            MessageSecurityMode::SignAndEncrypt,
        ),
        Policy::None => (SecurityPolicy::None, MessageSecurityMode::None),
    }
}

/// The server, configured (not yet running).
fn builder(
    machine: &MachineConfig,
    cfg: &OpcuaConfig,
    roles: Arc<Roles>,
    bridge: Handle,
) -> ServerBuilder {
    let mut b = ServerBuilder::new()
        .application_name("motion-opcua")
        .application_uri(pki::application_uri())
        .product_uri(NAMESPACE_URI)
        .host(cfg.host.clone())
        .port(cfg.port)
        .pki_dir(cfg.pki_dir.clone())
        .certificate_path(pki::CERT)
        .private_key_path(pki::KEY)
        .create_sample_keypair(false)
        .trust_client_certs(false)
        .check_cert_time(true)
        .discovery_urls(vec![cfg.endpoint.clone()])
        .subscription_poll_interval_ms(MIN_INTERVAL_MS as u64)
        .max_sessions(MAX_SESSIONS)
        .max_session_timeout_ms(MAX_SESSION_TIMEOUT_MS)
        .hello_timeout(HELLO_TIMEOUT_S)
        .with_authenticator(roles.clone())
        .with_node_manager(InMemoryNodeManagerBuilder::new(Builder {
            machine: machine.clone(),
            cfg: cfg.clone(),
            roles,
            bridge,
        }));
    let anon = [ANONYMOUS_USER_TOKEN_ID.to_string()];
    for p in &cfg.policies {
        let (policy, mode) = stack_policy(*p);
        b = b.add_endpoint(
            p.name(),
            ServerEndpoint::new(cfg.path.clone(), policy, mode, &anon),
        );
    }
    if let Some(p) = cfg.policies.iter().find(|p| **p != Policy::None) {
        b = b.default_endpoint(p.name());
    }
    let l = b.limits_mut();
    l.subscriptions.min_sampling_interval_ms = MIN_INTERVAL_MS;
    l.subscriptions.min_publishing_interval_ms = MIN_INTERVAL_MS;
    l.subscriptions.max_monitored_item_queue_size = MAX_QUEUE;
    l.subscriptions.max_subscriptions_per_session = MAX_SUBSCRIPTIONS_PER_SESSION;
    l.subscriptions.max_monitored_items_per_sub = MAX_MONITORED_ITEMS_PER_SUB;
    l.subscriptions.max_queued_notifications = MAX_QUEUED_NOTIFICATIONS;
    b
}

/// Serves until SIGINT/SIGTERM; on SIGHUP reads the users of `config` again
/// ([`reload_users`]). Returns the exit code.
pub async fn serve(
    machine: MachineConfig,
    cfg: OpcuaConfig,
    config: std::path::PathBuf,
) -> Result<(), String> {
    for u in &cfg.users {
        crate::password::parses(&u.password_hash)
            .map_err(|e| format!("[[opcua.user]] {}: password_hash: {e}", u.name))?;
    }
    if pki::ensure(&cfg.pki_dir, &cfg.host)? {
        log::info!(
            "created the server certificate {} and its key (0600)",
            cfg.pki_dir.join(pki::CERT).display()
        );
    }
    if cfg.offers_none() {
        log::warn!("the None policy is offered (configured): anonymous, read-only sessions there");
    }
    let roles = Arc::new(Roles::new(&cfg));
    let (tx, rx) = std::sync::mpsc::channel();
    let (server, handle) = builder(&machine, &cfg, roles.clone(), Handle { jobs: tx })
        .build()
        .map_err(|e| format!("OPC UA server: {e}"))?;
    let manager = handle
        .node_managers()
        .get_of_type::<InMemoryNodeManager<MachineManager>>()
        .ok_or("OPC UA server: our node manager is missing")?;
    let ns = handle
        .get_namespace_index(NAMESPACE_URI)
        .ok_or("OPC UA server: our namespace is missing")?;
    let publisher = Publisher::new(ns, manager, handle.subscriptions().clone());
    let stop = Arc::new(AtomicBool::new(false));
    let target = Target {
        prefix: machine.supervisor.service_prefix.clone(),
        runtime_dir: machine.supervisor.runtime_dir.clone(),
    };
    let bridge_stop = stop.clone();
    let thread = std::thread::Builder::new()
        .name("motion-bridge".into())
        .spawn(move || bridge::run(target, publisher, rx, bridge_stop))
        .map_err(|e| format!("cannot start the bridge thread: {e}"))?;
    let pki_dir = cfg.pki_dir.clone();
    tokio::spawn(async move {
        let mut tick = tokio::time::interval(std::time::Duration::from_secs(1));
        loop {
            tick.tick().await;
            let n = pki::prune_rejected(&pki_dir);
            if n > 0 {
                log::warn!(
                    "removed {n} files from rejected/ (at most {} kept)",
                    pki::MAX_REJECTED
                );
            }
        }
    });
    tokio::spawn(async move {
        use tokio::signal::unix::{signal, SignalKind};
        let Ok(mut hup) = signal(SignalKind::hangup()) else {
            return;
        };
        while hup.recv().await.is_some() {
            reload_users(&config, &roles);
        }
    });
    let h = handle.clone();
    tokio::spawn(async move {
        use tokio::signal::unix::{signal, SignalKind};
        let (Ok(mut int), Ok(mut term)) = (
            signal(SignalKind::interrupt()),
            signal(SignalKind::terminate()),
        ) else {
            return;
        };
        tokio::select! {
            _ = int.recv() => {}
            _ = term.recv() => {}
        }
        log::info!("stopping");
        h.cancel();
    });
    log::info!(
        "serving {} ({}) for the supervisor with service prefix {:?}",
        cfg.endpoint,
        cfg.policies
            .iter()
            .map(|p| p.name())
            .collect::<Vec<_>>()
            .join(", "),
        machine.supervisor.service_prefix
    );
    let r = server.run().await;
    stop.store(true, Ordering::Release);
    let _ = thread.join();
    r.map_err(|e| format!("OPC UA server: {e}"))
}

/// SIGHUP: the users of `[[opcua.user]]` (names, hashes, roles) read again
/// from `config`. A configuration that does not load, or a hash that does
/// not parse, changes nothing (said in the log).
pub fn reload_users(config: &std::path::Path, roles: &Roles) {
    let cfg = match motion_config::opcua::load(config) {
        Ok((_, cfg)) => cfg,
        Err(problems) => {
            let p: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
            log::warn!(
                "SIGHUP: {} does not load, the users stay as they were: {}",
                config.display(),
                p.join("; ")
            );
            return;
        }
    };
    for u in &cfg.users {
        if let Err(e) = crate::password::parses(&u.password_hash) {
            log::warn!(
                "SIGHUP: [[opcua.user]] {}: password_hash: {e}; the users stay as they were",
                u.name
            );
            return;
        }
    }
    let n = roles.reload(&cfg);
    log::info!(
        "SIGHUP: the users were read again from {} ({n})",
        config.display()
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Basic128Rsa15 and Basic256 (SHA-1, deprecated since OPC UA 1.04)
    /// cannot even be configured: no spelling of `policies` reaches them,
    /// and the secure ones are always Sign & Encrypt.
    #[test]
    fn deprecated_policies_are_never_offered() {
        for (name, p) in Policy::NAMES {
            let (policy, mode) = stack_policy(p);
            assert!(
                !matches!(
                    policy,
                    SecurityPolicy::Basic128Rsa15 | SecurityPolicy::Basic256
                ),
                "{name}"
            );
            if p != Policy::None {
                assert_eq!(mode, MessageSecurityMode::SignAndEncrypt, "{name}");
            }
        }
    }
}
