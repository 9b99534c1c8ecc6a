//! iceoryx2's `ZeroCopySend` for the two frames, with their versioned type
//! names, and the compile-time proof that every field may travel in shared
//! memory. Only with the `zero-copy` feature (see the crate documentation);
//! the three field types derive it in `frame.rs`.

use iceoryx2_bb_elementary_traits::zero_copy_send::ZeroCopySend;

use crate::frame::{
    AxisCommand, AxisFeedback, CommandFrame, FeedbackFrame, FrameHeader, COMMAND_FRAME_TYPE_NAME,
    FEEDBACK_FRAME_TYPE_NAME, MAX_AXES,
};
use crate::setpoint::{SetpointAxis, SetpointFrame, SETPOINT_FRAME_TYPE_NAME};

// SAFETY: `#[repr(C)]`, fields are `FrameHeader` and an array of `AxisCommand`,
// both `ZeroCopySend` (checked at compile time below), no pointers or
// process-local references, no implicit padding (size asserts in `frame.rs`).
// The type name carries the layout version so that processes with another
// layout are rejected by iceoryx2 when they open the service.
unsafe impl ZeroCopySend for CommandFrame {
    unsafe fn type_name() -> &'static str {
        COMMAND_FRAME_TYPE_NAME
    }
}

// SAFETY: as for `CommandFrame`; the extra fields are plain `u64`.
unsafe impl ZeroCopySend for FeedbackFrame {
    unsafe fn type_name() -> &'static str {
        FEEDBACK_FRAME_TYPE_NAME
    }
}

// SAFETY: as for `CommandFrame`: `#[repr(C)]`, integers and an array of
// `SetpointAxis` (ZeroCopySend, checked below), no implicit padding (asserts
// in `setpoint.rs`), the layout version in the type name.
unsafe impl ZeroCopySend for SetpointFrame {
    unsafe fn type_name() -> &'static str {
        SETPOINT_FRAME_TYPE_NAME
    }
}

const fn assert_zero_copy_send<T: ZeroCopySend + ?Sized>() {}

const _: () = {
    // Every field of the hand-implemented frames is ZeroCopySend.
    assert_zero_copy_send::<FrameHeader>();
    assert_zero_copy_send::<[AxisCommand; MAX_AXES]>();
    assert_zero_copy_send::<[AxisFeedback; MAX_AXES]>();
    assert_zero_copy_send::<u64>();
    assert_zero_copy_send::<[SetpointAxis; MAX_AXES]>();
};

#[cfg(test)]
mod tests {
    use core::mem::MaybeUninit;

    use iceoryx2_bb_elementary_traits::placement_default::PlacementDefault;

    use super::*;

    #[test]
    fn iceoryx2_sees_the_versioned_type_names() {
        // SAFETY: type_name() is only unsafe to implement, not to call.
        unsafe {
            assert_eq!(
                <CommandFrame as ZeroCopySend>::type_name(),
                COMMAND_FRAME_TYPE_NAME
            );
            assert_eq!(
                <FeedbackFrame as ZeroCopySend>::type_name(),
                FEEDBACK_FRAME_TYPE_NAME
            );
        }
    }

    #[test]
    fn placement_default_equals_default() {
        let mut c = MaybeUninit::<CommandFrame>::uninit();
        let mut f = MaybeUninit::<FeedbackFrame>::uninit();
        // SAFETY: pointers are valid, aligned, uninitialized memory of the type.
        let (c, f) = unsafe {
            CommandFrame::placement_default(c.as_mut_ptr());
            FeedbackFrame::placement_default(f.as_mut_ptr());
            (c.assume_init(), f.assume_init())
        };
        assert_eq!(c, CommandFrame::default());
        assert_eq!(f, FeedbackFrame::default());
    }
}
