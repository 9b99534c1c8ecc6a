//! Service names, made in one place.
//!
//! Inside a supervisor's domain (see [`crate::domain`]) with service prefix `P`:
//!
//! | service | pattern | writer → reader |
//! |---|---|---|
//! | `P/io/NAME/command` | publish-subscribe of [`motion_frames::CommandFrame`] | supervisor → I/O process `NAME` |
//! | `P/io/NAME/command_ready` | event | supervisor → I/O process ("a command was sent") |
//! | `P/io/NAME/feedback` | publish-subscribe of [`motion_frames::FeedbackFrame`] | I/O process → supervisor |
//! | `P/io/NAME/feedback_ready` | event | I/O process → supervisor |
//! | `P/control` | request-response (`motion-control`) | motionctl, HMIs → supervisor |
//! | `P/status` | publish-subscribe (`motion-control`), 100 Hz | supervisor → motionctl, HMIs |
//! | `P/setpoints` | publish-subscribe of [`motion_frames::SetpointFrame`] | programs owning axes (≤ 8) → supervisor |

/// The four frame services of one I/O process.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IoServiceNames {
    pub command: String,
    pub command_ready: String,
    pub feedback: String,
    pub feedback_ready: String,
}

impl IoServiceNames {
    pub fn new(prefix: &str, io: &str) -> Self {
        Self {
            command: format!("{prefix}/io/{io}/command"),
            command_ready: format!("{prefix}/io/{io}/command_ready"),
            feedback: format!("{prefix}/io/{io}/feedback"),
            feedback_ready: format!("{prefix}/io/{io}/feedback_ready"),
        }
    }

    pub fn all(&self) -> [&str; 4] {
        [
            &self.command,
            &self.command_ready,
            &self.feedback,
            &self.feedback_ready,
        ]
    }
}

/// `P/control`.
pub fn control_service(prefix: &str) -> String {
    format!("{prefix}/control")
}

/// `P/status`.
pub fn status_service(prefix: &str) -> String {
    format!("{prefix}/status")
}

/// `P/setpoints`.
pub fn setpoint_service(prefix: &str) -> String {
    format!("{prefix}/setpoints")
}
