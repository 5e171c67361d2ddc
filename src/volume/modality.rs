//! What kind of scanner made a volume, as its file says (NRRD `modality:=…`, DICOM `Modality`).
//! The defaults (transfer function, window) follow it; files that say nothing are judged by their
//! values instead (`transfer::fit`).

/// The imaging modality a file declares.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Modality {
    /// Medical CT (values meant as Hounsfield units, though not every file stores them so);
    /// `angio` for CT angiography.
    Ct {
        /// CT angiography (contrast-filled vessels are what matters).
        angio: bool,
    },
    /// Magnetic resonance; `angio` for MR angiography.
    Mr {
        /// MR angiography (bright vessels on a dark background).
        angio: bool,
    },
    /// CT of objects (industrial or micro-CT): attenuation without tissue or Hounsfield units.
    IndustrialCt,
    /// Anything else, as written (PET, ultrasound, microscopy, …).
    Other(String),
}

impl Modality {
    /// Reads a declared modality: `CT`, `CTA`, `CT (industrial)`, `MR`, `MRI`, `MRA`, DICOM codes;
    /// case and surrounding space do not matter. `None` for an empty text.
    pub fn parse(text: &str) -> Option<Self> {
        let t = text.trim();
        if t.is_empty() {
            return None;
        }
        let lower = t.to_ascii_lowercase();
        let word = lower
            .split(|c: char| !c.is_ascii_alphanumeric())
            .next()
            .unwrap_or("");
        let industrial = ["industrial", "micro", "µct", "object", "ndt"]
            .iter()
            .any(|w| lower.contains(w));
        Some(match word {
            "ct" | "cta" | "cbct" if industrial => Self::IndustrialCt,
            "ct" | "cbct" => Self::Ct { angio: false },
            "cta" => Self::Ct { angio: true },
            "mr" | "mri" => Self::Mr {
                angio: lower.contains("angio") || lower.contains("tof"),
            },
            "mra" => Self::Mr { angio: true },
            "microct" | "uct" => Self::IndustrialCt,
            _ => Self::Other(t.to_string()),
        })
    }

    /// The text [`Modality::parse`] reads back as this modality (`CT`, `CTA`, `MRA`, …), for
    /// writing files.
    pub fn code(&self) -> String {
        match self {
            Self::Ct { angio: false } => "CT".into(),
            Self::Ct { angio: true } => "CTA".into(),
            Self::Mr { angio: false } => "MR".into(),
            Self::Mr { angio: true } => "MRA".into(),
            Self::IndustrialCt => "CT (industrial)".into(),
            Self::Other(text) => text.clone(),
        }
    }

    /// A short name for messages: `CT`, `CT angiography`, `MR`, …
    pub fn label(&self) -> String {
        match self {
            Self::Ct { angio: false } => "CT".into(),
            Self::Ct { angio: true } => "CT angiography".into(),
            Self::Mr { angio: false } => "MR".into(),
            Self::Mr { angio: true } => "MR angiography".into(),
            Self::IndustrialCt => "industrial CT".into(),
            Self::Other(text) => text.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shared_datas_modalities_are_read() {
        assert_eq!(Modality::parse("CT"), Some(Modality::Ct { angio: false }));
        assert_eq!(Modality::parse(" cta "), Some(Modality::Ct { angio: true }));
        assert_eq!(
            Modality::parse("CT (industrial)"),
            Some(Modality::IndustrialCt)
        );
        assert_eq!(Modality::parse("MR"), Some(Modality::Mr { angio: false }));
        assert_eq!(Modality::parse("MRA"), Some(Modality::Mr { angio: true }));
        assert_eq!(
            Modality::parse("MR TOF angiography"),
            Some(Modality::Mr { angio: true })
        );
        assert_eq!(Modality::parse("PT"), Some(Modality::Other("PT".into())));
        assert_eq!(Modality::parse("  "), None);
        for m in [
            Modality::Ct { angio: true },
            Modality::Mr { angio: false },
            Modality::IndustrialCt,
            Modality::Other("US".into()),
        ] {
            assert_eq!(Modality::parse(&m.code()), Some(m.clone()));
        }
        // A word that only starts like CT is not CT.
        assert_eq!(
            Modality::parse("CTX scan"),
            Some(Modality::Other("CTX scan".into()))
        );
    }
}
