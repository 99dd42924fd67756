//! Anaglyph glasses as the front camera sees them: which coloured filter is over which eye.
//!
//! Plain data shared by the face tracker (`phantogram_vision`, which finds the filters) and the
//! engine (which uses them for distance and the glasses check). **Frames**: "left" and "right"
//! are the **viewer's** eyes. No threads, no panics.

/// One lens's colour: the filters of red/cyan, green/magenta and amber/blue glasses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Filter {
    Red,
    Cyan,
    Green,
    Magenta,
    Amber,
    Blue,
}

impl Filter {
    pub const ALL: [Filter; 6] = [
        Filter::Red,
        Filter::Cyan,
        Filter::Green,
        Filter::Magenta,
        Filter::Amber,
        Filter::Blue,
    ];

    /// The other lens of the same glasses.
    pub fn partner(self) -> Filter {
        match self {
            Filter::Red => Filter::Cyan,
            Filter::Cyan => Filter::Red,
            Filter::Green => Filter::Magenta,
            Filter::Magenta => Filter::Green,
            Filter::Amber => Filter::Blue,
            Filter::Blue => Filter::Amber,
        }
    }

    /// The lens that the usual way of wearing puts over the left eye (red, green, amber).
    pub fn is_left_by_convention(self) -> bool {
        matches!(self, Filter::Red | Filter::Green | Filter::Amber)
    }

    /// Lower-case name, as `phantogram eval face --json` writes it.
    pub fn name(self) -> &'static str {
        match self {
            Filter::Red => "red",
            Filter::Cyan => "cyan",
            Filter::Green => "green",
            Filter::Magenta => "magenta",
            Filter::Amber => "amber",
            Filter::Blue => "blue",
        }
    }
}

/// Glasses seen on the viewer's face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlassesSeen {
    /// The filter over the viewer's left eye and over the right eye (partners).
    pub left: Filter,
    pub right: Filter,
    /// How strongly the two lenses tint the skin they cover, the weaker of the two: the colour
    /// shift's size in natural-log units (0 for clear glass).
    pub strength: f32,
}

impl GlassesSeen {
    /// Worn the other way round: the usual left filter (red, green, amber) is over the right eye.
    pub fn swapped(&self) -> bool {
        !self.left.is_left_by_convention()
    }
}
