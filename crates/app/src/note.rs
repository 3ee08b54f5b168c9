//! Messages to the user on standard error that never fail the render: a closed or broken
//! stderr (`pathlight render 2>&1 | head -1`) must not turn into a panic or lose the image.

/// Like `eprintln!`, but a failed write is ignored.
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}
