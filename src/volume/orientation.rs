//! Where the patient's anatomical directions lie in the volume: which of right/left,
//! anterior/posterior, superior/inferior each index axis points to, read from the file's header
//! (NIfTI sform or qform, NRRD `space` and `space directions`) and reduced, as nibabel's
//! `aff2axcodes` does, to the closest anatomical direction per axis. The renderer's world frame is
//! the index frame scaled by the spacing, so an anatomical direction is a signed world axis.

use glam::DVec3;

/// An anatomical direction (the way an index axis increases).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Patient's right.
    Right,
    /// Patient's left.
    Left,
    /// Front (nose).
    Anterior,
    /// Back.
    Posterior,
    /// Head end.
    Superior,
    /// Feet end.
    Inferior,
}

impl Direction {
    /// All six, in the order views are offered (A, P, L, R, S, I).
    pub const VIEWS: [Self; 6] = [
        Self::Anterior,
        Self::Posterior,
        Self::Left,
        Self::Right,
        Self::Superior,
        Self::Inferior,
    ];

    /// Parses a view name: the letter (`A`, `p`, …) or the full name (`anterior`, …), in any
    /// case.
    pub fn parse(s: &str) -> Option<Self> {
        let s = s.to_ascii_lowercase();
        Self::VIEWS.into_iter().find(|d| {
            s == d.letter().to_ascii_lowercase().to_string() || s == d.name().to_lowercase()
        })
    }

    /// The opposite direction.
    pub(crate) fn opposite(self) -> Self {
        match self {
            Self::Right => Self::Left,
            Self::Left => Self::Right,
            Self::Anterior => Self::Posterior,
            Self::Posterior => Self::Anterior,
            Self::Superior => Self::Inferior,
            Self::Inferior => Self::Superior,
        }
    }

    /// One-letter code (R, L, A, P, S, I).
    pub(crate) fn letter(self) -> char {
        match self {
            Self::Right => 'R',
            Self::Left => 'L',
            Self::Anterior => 'A',
            Self::Posterior => 'P',
            Self::Superior => 'S',
            Self::Inferior => 'I',
        }
    }

    /// Full name, as in "Anterior".
    pub fn name(self) -> &'static str {
        match self {
            Self::Right => "Right",
            Self::Left => "Left",
            Self::Anterior => "Anterior",
            Self::Posterior => "Posterior",
            Self::Superior => "Superior",
            Self::Inferior => "Inferior",
        }
    }

    /// The direction a letter names (R, L, A, P, S, I, any case).
    fn from_letter(letter: char) -> Option<Self> {
        let upper = letter.to_ascii_uppercase();
        [
            Self::Right,
            Self::Left,
            Self::Anterior,
            Self::Posterior,
            Self::Superior,
            Self::Inferior,
        ]
        .into_iter()
        .find(|d| d.letter() == upper)
    }

    /// The RAS axis this direction lies on: 0 for R/L, 1 for A/P, 2 for S/I.
    fn ras_axis(self) -> usize {
        match self {
            Self::Right | Self::Left => 0,
            Self::Anterior | Self::Posterior => 1,
            Self::Superior | Self::Inferior => 2,
        }
    }

    /// The positive direction of RAS axis `a` (0 = R, 1 = A, 2 = S) or its negative.
    fn of_ras_axis(a: usize, positive: bool) -> Self {
        let d = [Self::Right, Self::Anterior, Self::Superior][a];
        if positive { d } else { d.opposite() }
    }
}

/// Who said which way the index axes point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrientationSource {
    /// The file's header.
    Header,
    /// The user, overriding the header or filling in for a file without one
    /// (`--orientation`, the window's orientation controls).
    User,
    /// Nobody: [`Orientation::ASSUMED`], for files without one.
    Assumed,
    /// Nobody, for an image without patient orientation (DICOM without
    /// ImageOrientationPatient or PatientOrientation): shown as stored, row 0 at the top and
    /// column 0 at the left ([`Orientation::AS_STORED`]); the letters are not the patient's.
    AsStored,
}

/// The anatomical direction of each index axis, and who said so.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Orientation {
    /// Direction in which index i, j, k increase.
    pub axes: [Direction; 3],
    /// Where it comes from.
    pub source: OrientationSource,
}

/// Why an orientation code was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "orientation {0:?} is not a code of three letters, one each of R/L, A/P and S/I, saying where \
     index axes i, j, k point (e.g. RAS, LPS, or RAI for slices that run from the top of the \
     head down)"
)]
pub struct BadOrientationCode(pub String);

impl Orientation {
    /// What files without orientation are taken to be: RAS, NIfTI's world convention (index
    /// i to the patient's right, j to the front, k to the head).
    pub const ASSUMED: Self = Self {
        axes: [Direction::Right, Direction::Anterior, Direction::Superior],
        source: OrientationSource::Assumed,
    };

    /// What an image without patient orientation is shown as: the axes DICOM's default plane
    /// (ImageOrientationPatient `1\0\0\0\1\0`) gives, which the axial view shows as stored,
    /// row 0 at the top and column 0 at the left.
    pub const AS_STORED: Self = Self {
        axes: [Direction::Left, Direction::Posterior, Direction::Superior],
        source: OrientationSource::AsStored,
    };

    /// Reads a three-letter code (`RAS`, `lpi`, …: any case) as the user's orientation: one
    /// letter of each pair R/L, A/P, S/I, for index axes i, j, k in turn.
    pub fn parse_code(code: &str) -> Result<Self, BadOrientationCode> {
        let bad = || BadOrientationCode(code.to_string());
        let letters: Vec<char> = code.trim().chars().collect();
        if letters.len() != 3 {
            return Err(bad());
        }
        let mut axes = [Direction::Right; 3];
        let mut taken = [false; 3];
        for (a, letter) in letters.iter().enumerate() {
            let d = Direction::from_letter(*letter).ok_or_else(bad)?;
            let pair = d.ras_axis();
            if taken[pair] {
                return Err(bad());
            }
            taken[pair] = true;
            axes[a] = d;
        }
        Ok(Self {
            axes,
            source: OrientationSource::User,
        })
    }

    /// The same axes, as said by `source`.
    pub(crate) fn said_by(mut self, source: OrientationSource) -> Self {
        self.source = source;
        self
    }

    /// The same orientation with the index axis that points along `direction`'s pair (R/L, A/P
    /// or S/I) pointing the other way: "this file's k axis points inferior, not superior". The
    /// result is the user's word.
    pub(crate) fn flipped(self, direction: Direction) -> Self {
        let flipped = match self
            .axes
            .iter()
            .position(|d| d.ras_axis() == direction.ras_axis())
        {
            Some(axis) => self.with_axis_reversed(axis),
            None => self,
        };
        flipped.said_by(OrientationSource::User)
    }

    /// From the world (RAS) direction of each index axis, `columns[a]` for axis a: each axis
    /// takes the RAS axis it is closest to. `None` when the columns are degenerate (zero, not
    /// finite, or two axes closest to the same RAS axis).
    pub fn from_ras_columns(columns: [[f64; 3]; 3]) -> Option<Self> {
        let mut taken = [false; 3];
        let mut axes = [Direction::Right; 3];
        for (a, c) in columns.iter().enumerate() {
            if c.iter().any(|v| !v.is_finite()) {
                return None;
            }
            let (best, value) = (0..3)
                .map(|r| (r, c[r]))
                .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))?;
            if value == 0.0 || taken[best] {
                return None;
            }
            taken[best] = true;
            axes[a] = Direction::of_ras_axis(best, value > 0.0);
        }
        Some(Self {
            axes,
            source: OrientationSource::Header,
        })
    }

    /// From the direction of each index axis in LPS coordinates (DICOM's, and NRRD's
    /// `left-posterior-superior` space).
    pub(crate) fn from_lps_columns(columns: [[f64; 3]; 3]) -> Option<Self> {
        Self::from_ras_columns(columns.map(|[x, y, z]| [-x, -y, z]))
    }

    /// Three-letter code, e.g. `RAS` or `LPI`.
    pub fn code(&self) -> String {
        self.axes.iter().map(|d| d.letter()).collect()
    }

    /// The world (index-frame) unit vector pointing towards `direction`.
    pub fn world(&self, direction: Direction) -> DVec3 {
        for (a, d) in self.axes.iter().enumerate() {
            let sign = if *d == direction {
                1.0
            } else if d.opposite() == direction {
                -1.0
            } else {
                continue;
            };
            let mut v = DVec3::ZERO;
            v[a] = sign;
            return v;
        }
        // Every orientation built here covers all three RAS axes once.
        DVec3::ZERO
    }

    /// Whether the index frame is a mirror image of the patient (an odd number of flipped
    /// axes): the 3D picture of such a volume is mirrored.
    pub fn is_mirrored(&self) -> bool {
        let r = self.world(Direction::Right);
        let a = self.world(Direction::Anterior);
        let s = self.world(Direction::Superior);
        r.cross(a).dot(s) < 0.0
    }

    /// The same orientation with index axis `axis` (0, 1 or 2) pointing the other way.
    pub(crate) fn with_axis_reversed(mut self, axis: usize) -> Self {
        if let Some(d) = self.axes.get_mut(axis) {
            *d = d.opposite();
        }
        self
    }

    /// Camera direction and up vector of the standard view *from* `side`: the eye on that side
    /// of the patient looking across; superior up for A, P, L, R, anterior up for S and I (as 3D
    /// Slicer's view buttons).
    pub fn view_from(&self, side: Direction) -> (DVec3, DVec3) {
        let up = match side {
            Direction::Superior | Direction::Inferior => Direction::Anterior,
            _ => Direction::Superior,
        };
        (self.world(side.opposite()), self.world(up))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ras_identity_and_lps_flip() {
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let ras = Orientation::from_ras_columns(identity).expect("valid");
        assert_eq!(ras.code(), "RAS");
        assert!(!ras.is_mirrored());
        let lps = Orientation::from_lps_columns(identity).expect("valid");
        assert_eq!(lps.code(), "LPS");
        assert!(!lps.is_mirrored(), "LPS is a rotation of RAS");
        let las =
            Orientation::from_ras_columns([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
                .expect("valid");
        assert_eq!(las.code(), "LAS");
        assert!(las.is_mirrored());
    }

    #[test]
    fn oblique_axes_take_the_closest_direction() {
        // A 20° tilt about x, with 0.8 mm spacing on i and a swap of j and k (coronal slices).
        let (s, c) = 20f64.to_radians().sin_cos();
        let columns = [[0.8, 0.0, 0.0], [0.0, -s, -c], [0.0, c, -s]];
        let o = Orientation::from_ras_columns(columns).expect("valid");
        assert_eq!(o.code(), "RIA");
        assert_eq!(o.world(Direction::Superior), DVec3::new(0.0, -1.0, 0.0));
        assert_eq!(o.world(Direction::Posterior), DVec3::new(0.0, 0.0, -1.0));
    }

    #[test]
    fn degenerate_columns_give_none() {
        let zero = [[0.0; 3], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(Orientation::from_ras_columns(zero).is_none());
        let twice = [[1.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.0, 0.0, 1.0]];
        assert!(Orientation::from_ras_columns(twice).is_none());
        let nan = [[f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(Orientation::from_ras_columns(nan).is_none());
    }

    #[test]
    fn codes_parse_one_letter_of_each_pair() {
        let rai = Orientation::parse_code("rai").expect("valid");
        assert_eq!(rai.code(), "RAI");
        assert_eq!(rai.source, OrientationSource::User);
        assert!(rai.is_mirrored(), "RAI is RAS with k reversed");
        assert_eq!(
            Orientation::parse_code(" LPS ").expect("valid").code(),
            "LPS"
        );
        assert_eq!(Orientation::parse_code("SAR").expect("valid").code(), "SAR");
        for bad in ["", "RA", "RASR", "RRS", "RLA", "RAX", "R A", "ÄAS"] {
            let e = Orientation::parse_code(bad).expect_err(bad);
            assert!(e.to_string().contains("R/L, A/P and S/I"), "{e}");
        }
    }

    #[test]
    fn flipping_a_direction_reverses_the_axis_along_it() {
        let ras = Orientation::ASSUMED;
        assert_eq!(ras.flipped(Direction::Superior).code(), "RAI");
        assert_eq!(ras.flipped(Direction::Inferior).code(), "RAI");
        assert_eq!(ras.flipped(Direction::Anterior).code(), "RPS");
        assert_eq!(ras.flipped(Direction::Left).code(), "LAS");
        let sar = Orientation::parse_code("SAR").expect("valid");
        assert_eq!(sar.flipped(Direction::Superior).code(), "IAR");
        assert_eq!(ras.flipped(Direction::Left).source, OrientationSource::User);
        // Twice is the identity.
        for d in Direction::VIEWS {
            assert_eq!(ras.flipped(d).flipped(d).axes, ras.axes);
        }
    }

    #[test]
    fn view_names_parse_in_any_case() {
        assert_eq!(Direction::parse("A"), Some(Direction::Anterior));
        assert_eq!(Direction::parse("inferior"), Some(Direction::Inferior));
        assert_eq!(Direction::parse("Left"), Some(Direction::Left));
        assert_eq!(Direction::parse("x"), None);
        assert_eq!(Direction::parse(""), None);
    }

    #[test]
    fn views_look_across_the_patient_with_the_head_up() {
        let o = Orientation::ASSUMED;
        for side in Direction::VIEWS {
            let (dir, up) = o.view_from(side);
            // The eye is on `side`: it looks towards the opposite side.
            assert_eq!(dir, -o.world(side), "{side:?}");
            assert_eq!(dir.dot(up), 0.0, "{side:?}: up is across the view");
            assert_eq!(up.length(), 1.0);
        }
        assert_eq!(o.view_from(Direction::Anterior).1, DVec3::Z);
        assert_eq!(o.view_from(Direction::Superior).1, DVec3::Y);
    }
}
