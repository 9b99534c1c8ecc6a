//! Our node manager: the address space of `urn:motion-supervisor` (built
//! once from the config, [`crate::nodes`]) and the method calls, which
//! check the caller's role, decode the arguments ([`crate::methods`]), ask
//! the daemon through the bridge thread and answer with its words.
//!
//! Every refused call is logged with the session's identity: user, role,
//! client application URI, session name, security policy and the client
//! certificate's thumbprint.

use crate::auth::Roles;
use crate::bridge::{BridgeError, Handle};
use crate::jogs::Watch;
use crate::methods::{self, CallError, MethodSpec, Scope};
use crate::space::NAMESPACE_URI;
use async_trait::async_trait;
use motion_config::names::shown;
use motion_config::opcua::OpcuaConfig;
use motion_config::MachineConfig;
use opcua::server::address_space::AddressSpace;
use opcua::server::diagnostics::NamespaceMetadata;
use opcua::server::node_manager::memory::{
    InMemoryNodeManagerImpl, InMemoryNodeManagerImplBuilder,
};
use opcua::server::node_manager::{MethodCall, RequestContext, ServerContext};
use opcua::sync::RwLock;
use opcua::types::{Identifier, MessageSecurityMode, NodeId, StatusCode};
use std::sync::Arc;
use std::time::Instant;

pub struct MachineManager {
    ns: u16,
    /// The trust list: a session whose client certificate left it calls
    /// nothing any more.
    pki: std::path::PathBuf,
    axes: Vec<String>,
    roles: Arc<Roles>,
    bridge: Handle,
}

/// Builds [`MachineManager`] (and the address space) when the server starts.
pub struct Builder {
    pub machine: MachineConfig,
    pub cfg: OpcuaConfig,
    pub roles: Arc<Roles>,
    pub bridge: Handle,
}

impl InMemoryNodeManagerImplBuilder for Builder {
    type Impl = MachineManager;

    fn build(self, context: ServerContext, space: &mut AddressSpace) -> MachineManager {
        let ns = context
            .type_tree
            .write()
            .namespaces_mut()
            .add_namespace(NAMESPACE_URI);
        space.add_namespace(NAMESPACE_URI, ns);
        crate::nodes::build(space, ns, &self.machine, &self.cfg);
        MachineManager {
            ns,
            pki: self.cfg.pki_dir.clone(),
            axes: self.machine.axes.iter().map(|a| a.name.clone()).collect(),
            roles: self.roles,
            bridge: self.bridge,
        }
    }
}

impl MachineManager {
    /// The method a node id names: `Machine.<M>` or `Machine.Axes.<axis>.<M>`.
    fn lookup(&self, id: &NodeId) -> Option<(&'static MethodSpec, Option<String>)> {
        if id.namespace != self.ns {
            return None;
        }
        let Identifier::String(s) = &id.identifier else {
            return None;
        };
        let s = s.as_ref();
        if let Some(rest) = s.strip_prefix("Machine.Axes.") {
            let (key, m) = rest.rsplit_once('.')?;
            let axis = self
                .axes
                .iter()
                .find(|a| crate::space::axis_key(a) == key)?;
            return methods::spec(m, Scope::Axis).map(|spec| (spec, Some(axis.clone())));
        }
        let m = s.strip_prefix("Machine.")?;
        methods::spec(m, Scope::Machine).map(|spec| (spec, None))
    }

    /// How the bridge tells that the caller of a hold-to-run call may still
    /// run it, checked between its calls: its session is still in the
    /// server's session table (a closed or expired session is dropped from
    /// it) and not past its timeout, its client certificate is still
    /// trusted, and its user still has the operator role (the users are
    /// read again on SIGHUP) — what a call is checked for.
    fn watch(&self, ctx: &RequestContext) -> Watch {
        let session = Arc::downgrade(&ctx.session);
        let (roles, pki, token) = (
            self.roles.clone(),
            self.pki.clone(),
            ctx.user_token().clone(),
        );
        Watch {
            session: ctx.session_id(),
            may_run: Box::new(move || {
                let Some(s) = session.upgrade() else {
                    return Err("the session that started it is gone");
                };
                let s = s.read();
                if !s.is_activated() || s.deadline() <= Instant::now() {
                    return Err("the session that started it is gone");
                }
                if s.client_certificate()
                    .is_some_and(|c| !crate::pki::still_trusted(&pki, c))
                {
                    return Err("its client certificate is no longer trusted");
                }
                if !roles.may_call(&token) {
                    return Err("its user is no longer an operator");
                }
                Ok(())
            }),
        }
    }

    /// The caller, in words, for the log.
    fn who(&self, ctx: &RequestContext) -> String {
        let s = ctx.session().read();
        let thumb = s
            .client_certificate()
            .map(|c| c.thumbprint().as_hex_string())
            .unwrap_or_else(|| "none".into());
        // The application URI and session name are the client's text:
        // shown escaped (no control characters reach the log).
        format!(
            "user {} [{}], client {} session {}, {} {:?}, certificate {thumb}",
            if ctx.user_token().is_anonymous() {
                "anonymous".to_string()
            } else {
                ctx.user_token().0.clone()
            },
            self.roles.role_of(ctx.user_token()),
            shown(s.application_description().application_uri.as_ref()),
            shown(s.session_name()),
            s.security_policy_uri().rsplit('#').next().unwrap_or(""),
            s.message_security_mode(),
        )
    }

    async fn one(&self, ctx: &RequestContext, call: &mut MethodCall) {
        let Some((spec, axis)) = self.lookup(call.method_id()) else {
            call.set_status(StatusCode::BadMethodInvalid);
            return;
        };
        let what = match &axis {
            Some(a) => format!("{} on axis {a}", spec.name),
            None => spec.name.to_string(),
        };
        let secure =
            ctx.session().read().message_security_mode() == MessageSecurityMode::SignAndEncrypt;
        let revoked = (ctx.session().read().client_certificate())
            .is_some_and(|c| !crate::pki::still_trusted(&self.pki, c));
        if revoked {
            log::warn!(
                "OPC UA call {what} refused (BadUserAccessDenied: the client certificate is no longer trusted): {}",
                self.who(ctx)
            );
            call.set_status(StatusCode::BadUserAccessDenied);
            return;
        }
        if !secure || !self.roles.may_call(ctx.user_token()) {
            log::warn!(
                "OPC UA call {what} refused (BadUserAccessDenied: {}): {}",
                if secure {
                    "not an operator"
                } else {
                    "not over Sign & Encrypt"
                },
                self.who(ctx)
            );
            call.set_status(StatusCode::BadUserAccessDenied);
            return;
        }
        let op = match methods::decode(spec, axis.as_deref(), call.arguments()) {
            Ok(op) => op,
            Err(e) => {
                log::warn!(
                    "OPC UA call {what} refused (bad arguments {e:?}): {}",
                    self.who(ctx)
                );
                match e {
                    CallError::Status(s) => call.set_status(s),
                    CallError::Args(a) => call.set_argument_error(a),
                }
                return;
            }
        };
        let held = matches!(spec.verb, methods::Verb::Op(k) if k.held());
        let watch = held.then(|| self.watch(ctx));
        match self.bridge.run_watched(op, watch).await {
            Ok(resp) => {
                let status = methods::status_of(&resp);
                call.set_outputs(methods::outputs(spec.scope, &resp));
                call.set_status(status);
                if status.is_good() {
                    log::info!("OPC UA call {what} accepted: {}", self.who(ctx));
                } else {
                    log::warn!(
                        "OPC UA call {what} refused by the supervisor ({status}: {}): {}",
                        describe(&resp),
                        self.who(ctx)
                    );
                }
            }
            Err(e) => {
                let status = match e {
                    BridgeError::NoDaemon(_) => StatusCode::BadNoCommunication,
                    BridgeError::Failed(_) => StatusCode::BadInternalError,
                };
                log::warn!("OPC UA call {what} failed ({e:?}): {}", self.who(ctx));
                call.set_status(status);
            }
        }
    }
}

/// The refusal's reasons in one line.
fn describe(resp: &motion_control::ControlResponse) -> String {
    let mut parts: Vec<String> = resp
        .answers()
        .iter()
        .filter(|a| a.accepted == 0)
        .map(|a| {
            format!(
                "{}: {} (ERR {} EXERR {})",
                motion_control::get_str(&a.name),
                motion_control::reason_text(a.reason),
                a.err,
                a.exerr
            )
        })
        .collect();
    let msg = resp.message_text();
    if !msg.is_empty() {
        parts.push(msg);
    }
    parts.join("; ")
}

#[async_trait]
impl InMemoryNodeManagerImpl for MachineManager {
    async fn init(&self, _space: &mut AddressSpace, _context: ServerContext) {}

    fn name(&self) -> &str {
        "motion-supervisor"
    }

    fn namespaces(&self) -> Vec<NamespaceMetadata> {
        vec![NamespaceMetadata {
            namespace_uri: NAMESPACE_URI.to_string(),
            namespace_index: self.ns,
            ..Default::default()
        }]
    }

    async fn call(
        &self,
        context: &RequestContext,
        _space: &RwLock<AddressSpace>,
        methods_to_call: &mut [&mut &mut MethodCall],
    ) -> Result<(), StatusCode> {
        for m in methods_to_call.iter_mut() {
            self.one(context, m).await;
        }
        Ok(())
    }
}
