//! The keys that move the camera, held or scripted: W A S D along and across the view, Q and E
//! down and up, shift for fast.

use std::collections::BTreeSet;

use winit::keyboard::KeyCode;

use super::camera::Motion;

/// A movement key: its name in scripts, its key code, and what it adds to a [`Motion`].
type MovementKey = (&'static str, KeyCode, fn(&mut Motion));

/// Every movement key.
const MOVEMENT_KEYS: [MovementKey; 8] = [
    ("w", KeyCode::KeyW, |m| m.forward += 1.0),
    ("s", KeyCode::KeyS, |m| m.forward -= 1.0),
    ("d", KeyCode::KeyD, |m| m.right += 1.0),
    ("a", KeyCode::KeyA, |m| m.right -= 1.0),
    ("e", KeyCode::KeyE, |m| m.up += 1.0),
    ("q", KeyCode::KeyQ, |m| m.up -= 1.0),
    ("shift", KeyCode::ShiftLeft, |m| m.fast = true),
    ("shift", KeyCode::ShiftRight, |m| m.fast = true),
];

/// The movement keys held down now.
#[derive(Default)]
pub struct HeldKeys(BTreeSet<usize>);

impl HeldKeys {
    /// Records a press or release of `code`; false when it is not a movement key.
    pub fn update(&mut self, code: KeyCode, pressed: bool) -> bool {
        let Some(index) = MOVEMENT_KEYS.iter().position(|(_, c, _)| *c == code) else {
            return false;
        };
        if pressed {
            self.0.insert(index);
        } else {
            self.0.remove(&index);
        }
        true
    }

    /// Lets go of every key (the window lost the focus).
    pub fn clear(&mut self) {
        self.0.clear();
    }

    /// The movement the held keys ask for.
    pub fn motion(&self) -> Motion {
        let mut motion = Motion::default();
        self.0
            .iter()
            .for_each(|&i| (MOVEMENT_KEYS[i].2)(&mut motion));
        motion
    }
}

/// The movement asked for by the keys `names` (as scripts name them).
pub fn motion_of_names<'a>(names: impl Iterator<Item = &'a str>) -> Result<Motion, String> {
    let mut motion = Motion::default();
    for name in names {
        let Some((_, _, add)) = MOVEMENT_KEYS
            .iter()
            .find(|(n, _, _)| n.eq_ignore_ascii_case(name))
        else {
            return Err(format!(
                "`{name}` is not a movement key; allowed w, a, s, d, q, e, shift"
            ));
        };
        add(&mut motion);
    }
    Ok(motion)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_keys_add_up_and_releases_take_away() {
        let mut keys = HeldKeys::default();
        assert!(keys.update(KeyCode::KeyW, true));
        assert!(keys.update(KeyCode::KeyD, true));
        assert!(keys.update(KeyCode::ShiftLeft, true));
        assert!(!keys.update(KeyCode::KeyZ, true));
        let motion = keys.motion();
        assert_eq!(
            (motion.forward, motion.right, motion.fast),
            (1.0, 1.0, true)
        );
        keys.update(KeyCode::KeyW, false);
        keys.update(KeyCode::KeyS, true);
        keys.update(KeyCode::KeyQ, true);
        let motion = keys.motion();
        assert_eq!((motion.forward, motion.up), (-1.0, -1.0));
        keys.clear();
        assert_eq!(keys.motion(), Motion::default());
    }
}
