//! A scene's contact handling: whether spheres of different swimmers may overlap, and the steric
//! repulsion if any.

use super::steric::Steric;
use crate::engine::choice::{self, Choice, Named};
use serde::{Deserialize, Serialize};

/// Contact handling of a scene (saved with it).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Contacts {
    /// Let spheres of different swimmers overlap instead of stopping the run.
    pub allow_overlap: bool,
    /// Steric repulsion between spheres of different swimmers (microscopic and averaged models).
    pub steric: Option<Steric>,
}

impl Contacts {
    /// What touching spheres of different swimmers do.
    pub fn overlaps(&self) -> Overlaps {
        if self.allow_overlap {
            Overlaps::Allow
        } else {
            Overlaps::Stop
        }
    }
}

/// What happens when spheres of different swimmers touch (saved as [`Contacts::allow_overlap`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Overlaps {
    /// The run stops with an error naming the two spheres.
    #[default]
    Stop,
    /// They overlap, moved by the RPY tensor for overlapping spheres.
    Allow,
}

impl Named for Overlaps {
    const KIND: &'static str = "overlaps setting";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Overlaps::Stop,
            name: "stop",
            about: "default: the run stops when spheres of different swimmers touch",
        },
        Choice {
            value: Overlaps::Allow,
            name: "allow",
            about: "they overlap, moved by the RPY tensor for overlapping spheres",
        },
    ];
}

choice::inherent_names!(Overlaps);
