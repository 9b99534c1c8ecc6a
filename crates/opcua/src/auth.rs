//! Who may connect and what they may do.
//!
//! * Every secure endpoint (Sign & Encrypt) needs a client certificate in
//!   the trust list first (the stack checks it against `pki_dir/trusted`
//!   on every connection: `motion-opcua trust` takes effect at once).
//! * Anonymous sessions read (unless `anonymous = "off"`); the `None`
//!   endpoint, when configured, admits only them.
//! * Users log in with a name and password checked against the argon2
//!   hash of `[[opcua.user]]`; role "operator" may call methods, "viewer"
//!   may not ([`Roles::may_call`], applied in `manager.rs`, which logs
//!   every refused call with the session's identity, and checked again for
//!   every running hold-to-run jog by the bridge).
//! * The users and their roles are read again on SIGHUP
//!   ([`Roles::reload`]): a user removed or made a viewer calls nothing
//!   more, and a jog it holds stops at once. (The rest of `[opcua]` takes
//!   a restart.)
//!
//! Every refused login is logged here with the name the client gave and
//! the endpoint it used.

use crate::password;
use async_trait::async_trait;
use motion_config::opcua::{OpcuaConfig, Role, User};
use opcua::crypto::SecurityPolicy;
use opcua::server::authenticator::{
    user_pass_security_policy_id, AuthManager, Password, UserToken,
};
use opcua::server::ServerEndpoint;
use opcua::types::{
    Error, MessageSecurityMode, NodeId, StatusCode, UAString, UserTokenPolicy, UserTokenType,
};
use std::sync::RwLock;

/// The anonymous token's policy id (the stack's spelling).
const ANONYMOUS_POLICY: &str = "anonymous";

/// The users and the anonymous rule of `[opcua]`.
pub struct Roles {
    users: RwLock<Vec<User>>,
    anonymous: bool,
    verifying: tokio::sync::Semaphore,
}

/// Password checks running at once.
pub const VERIFYING: usize = 2;

impl Roles {
    pub fn new(cfg: &OpcuaConfig) -> Self {
        Self {
            users: RwLock::new(cfg.users.clone()),
            anonymous: cfg.anonymous,
            verifying: tokio::sync::Semaphore::new(VERIFYING),
        }
    }

    /// The users now (a poisoned lock still holds the last list set).
    fn users(&self) -> std::sync::RwLockReadGuard<'_, Vec<User>> {
        self.users.read().unwrap_or_else(|p| p.into_inner())
    }

    /// The users of `cfg` from now on (its password hashes already
    /// checked); how many there are.
    pub fn reload(&self, cfg: &OpcuaConfig) -> usize {
        let mut users = self.users.write().unwrap_or_else(|p| p.into_inner());
        *users = cfg.users.clone();
        users.len()
    }

    /// May the session of `token` call methods?
    pub fn may_call(&self, token: &UserToken) -> bool {
        !token.is_anonymous()
            && self
                .users()
                .iter()
                .any(|u| u.name == token.0 && u.role == Role::Operator)
    }

    /// The role of `token` in words (for the log).
    pub fn role_of(&self, token: &UserToken) -> &'static str {
        if token.is_anonymous() {
            return "anonymous (read-only)";
        }
        let role = self
            .users()
            .iter()
            .find(|u| u.name == token.0)
            .map(|u| u.role);
        match role {
            Some(Role::Operator) => "operator",
            Some(Role::Viewer) => "viewer (read-only)",
            None => "unknown",
        }
    }
}

fn is_none(endpoint: &ServerEndpoint) -> bool {
    endpoint.security_policy() == SecurityPolicy::None
        || endpoint.message_security_mode() == MessageSecurityMode::None
}

fn refuse(status: StatusCode, what: String) -> Error {
    log::warn!("OPC UA login refused: {what}");
    Error::new(status, what)
}

#[async_trait]
impl AuthManager for Roles {
    async fn authenticate_anonymous_token(&self, endpoint: &ServerEndpoint) -> Result<(), Error> {
        if self.anonymous {
            Ok(())
        } else {
            Err(refuse(
                StatusCode::BadIdentityTokenRejected,
                format!(
                    "anonymous session on {} {} (anonymous = \"off\")",
                    endpoint.path, endpoint.security_policy
                ),
            ))
        }
    }

    async fn authenticate_username_identity_token(
        &self,
        endpoint: &ServerEndpoint,
        username: &str,
        password: &Password,
    ) -> Result<UserToken, Error> {
        let shown = motion_config::names::shown(username);
        if is_none(endpoint) {
            return Err(refuse(
                StatusCode::BadIdentityTokenRejected,
                format!("user {shown} on the None endpoint (anonymous only there)"),
            ));
        }
        let user = self.users().iter().find(|u| u.name == username).cloned();
        // Verified even for an unknown name (against a fixed hash), so the
        // time taken does not tell which names exist.
        let hash = user.as_ref().map(|u| u.password_hash.clone());
        let given = password.get().to_string();
        // At most VERIFYING checks at once (each takes argon2's memory and
        // tens of ms of CPU): a flood of logins waits here instead of
        // taking the host's memory and both cores from the daemon's clients.
        let _turn = self.verifying.acquire().await;
        let ok = tokio::task::spawn_blocking(move || password::verify(hash.as_deref(), &given))
            .await
            .unwrap_or(false);
        match user {
            Some(u) if ok => {
                log::info!(
                    "OPC UA login: user {} ({}) on {}",
                    u.name,
                    self.role_of(&UserToken(u.name.clone())),
                    endpoint.security_policy
                );
                Ok(UserToken(u.name.clone()))
            }
            Some(_) => Err(refuse(
                StatusCode::BadUserAccessDenied,
                format!(
                    "user {shown} on {}: wrong password",
                    endpoint.security_policy
                ),
            )),
            None => Err(refuse(
                StatusCode::BadUserAccessDenied,
                format!("user {shown} on {}: no such user", endpoint.security_policy),
            )),
        }
    }

    /// The stack's own check stays permissive: the roles are applied where
    /// the refusal can be logged with the whole session (`manager.rs`).
    fn is_user_executable(&self, _token: &UserToken, _method_id: &NodeId) -> bool {
        true
    }

    fn user_token_policies(&self, endpoint: &ServerEndpoint) -> Vec<UserTokenPolicy> {
        let mut out = Vec::new();
        if self.anonymous {
            out.push(UserTokenPolicy {
                policy_id: UAString::from(ANONYMOUS_POLICY),
                token_type: UserTokenType::Anonymous,
                issued_token_type: UAString::null(),
                issuer_endpoint_url: UAString::null(),
                security_policy_uri: UAString::null(),
            });
        }
        if !is_none(endpoint) && !self.users().is_empty() {
            out.push(UserTokenPolicy {
                policy_id: user_pass_security_policy_id(endpoint),
                token_type: UserTokenType::UserName,
                issued_token_type: UAString::null(),
                issuer_endpoint_url: UAString::null(),
                // The endpoint's own policy encrypts the password.
                security_policy_uri: UAString::null(),
            });
        }
        out
    }
}
