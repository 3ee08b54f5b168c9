//! The viewer's input: mouse and keys turned into [`Action`]s (README lists them).

use winit::dpi::PhysicalPosition;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta};
use winit::keyboard::{Key, ModifiersState, NamedKey};

/// Pointer travel (pixels) that turns a press into a drag instead of a click.
const DRAG_THRESHOLD: f64 = 4.0;

/// What the user asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Action {
    /// Close the window (`Esc`).
    Quit,
    /// Pause or resume rendering (`Space`).
    TogglePause,
    /// Save the image (`S`).
    Save,
    /// Start the image over (`R`).
    Restart,
    /// The next tone mapper (`T`).
    CycleTonemap,
    /// Show the denoised image or the raw one (`D`).
    ToggleDenoised,
    /// Start the next iteration (right click).
    NextIteration,
    /// Toggle the object under this window point between light and material (left click).
    Click(PhysicalPosition<f64>),
    /// Focus the lens on the surface under this window point (`F`, or ctrl + left click).
    Focus(PhysicalPosition<f64>),
    /// Open (> 1) or close (< 1) the lens by this factor (`]`, `[`).
    Aperture(f32),
    /// Orbit by this many pixels dragged (left drag).
    Orbit(f32, f32),
    /// Pan by this many pixels dragged (middle drag, or shift + left drag).
    Pan(f32, f32),
    /// Zoom by this many wheel steps.
    Zoom(f32),
}

/// Pointer state for clicks and drags.
#[derive(Debug, Default)]
pub struct Pointer {
    position: PhysicalPosition<f64>,
    /// Where the left or middle button went down, and whether it has become a drag.
    pressed_at: Option<PhysicalPosition<f64>>,
    dragging: bool,
    left: bool,
    middle: bool,
    modifiers: ModifiersState,
}

impl Pointer {
    /// The modifier keys changed.
    pub fn set_modifiers(&mut self, modifiers: ModifiersState) {
        self.modifiers = modifiers;
    }

    /// The pointer moved to `position`: a drag past the threshold orbits or pans.
    pub fn moved(&mut self, position: PhysicalPosition<f64>) -> Option<Action> {
        let (dx, dy) = (
            (position.x - self.position.x) as f32,
            (position.y - self.position.y) as f32,
        );
        self.position = position;
        let start = self.pressed_at?;
        if !self.dragging {
            let travel = (position.x - start.x).hypot(position.y - start.y);
            if travel < DRAG_THRESHOLD {
                return None;
            }
            self.dragging = true;
        }
        if self.middle || self.modifiers.shift_key() {
            Some(Action::Pan(dx, dy))
        } else if self.left {
            Some(Action::Orbit(dx, dy))
        } else {
            None
        }
    }

    /// A button went down or up: a left press and release without a drag is a click, a
    /// right press asks for the next iteration.
    pub fn button(&mut self, state: ElementState, button: MouseButton) -> Option<Action> {
        let pressed = state == ElementState::Pressed;
        match button {
            MouseButton::Left | MouseButton::Middle => {
                if button == MouseButton::Left {
                    self.left = pressed;
                } else {
                    self.middle = pressed;
                }
                if pressed {
                    self.pressed_at = Some(self.position);
                    self.dragging = false;
                    return None;
                }
                let was_click = !self.dragging && self.pressed_at.is_some();
                self.pressed_at = None;
                self.dragging = false;
                if !was_click || button != MouseButton::Left {
                    return None;
                }
                Some(if self.modifiers.control_key() {
                    Action::Focus(self.position)
                } else {
                    Action::Click(self.position)
                })
            }
            MouseButton::Right if pressed => Some(Action::NextIteration),
            _ => None,
        }
    }

    /// Where the pointer is.
    pub fn position(&self) -> PhysicalPosition<f64> {
        self.position
    }
}

/// Factor by which `]` opens and `[` closes the lens.
pub const APERTURE_STEP: f32 = 1.5;

/// The action of a key press with the pointer at `pointer` (releases do nothing; `[` and `]`
/// repeat while held, other keys do not).
pub fn key_action(event: &KeyEvent, pointer: PhysicalPosition<f64>) -> Option<Action> {
    if event.state != ElementState::Pressed {
        return None;
    }
    let action = match &event.logical_key {
        Key::Named(NamedKey::Escape) => Action::Quit,
        Key::Named(NamedKey::Space) => Action::TogglePause,
        Key::Character(c) => match c.to_lowercase().as_str() {
            "s" => Action::Save,
            "r" => Action::Restart,
            "t" => Action::CycleTonemap,
            "d" => Action::ToggleDenoised,
            "f" => Action::Focus(pointer),
            "]" => Action::Aperture(APERTURE_STEP),
            "[" => Action::Aperture(1.0 / APERTURE_STEP),
            _ => return None,
        },
        _ => return None,
    };
    (!event.repeat || matches!(action, Action::Aperture(_))).then_some(action)
}

/// The zoom of a wheel turn, in steps.
pub fn wheel_action(delta: MouseScrollDelta) -> Action {
    Action::Zoom(match delta {
        MouseScrollDelta::LineDelta(_, y) => y,
        MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
    })
}
