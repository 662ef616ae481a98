//! The engineering objects of a model (`[[geology.tunnels]]`, `[[geology.excavations]]`,
//! `[[geology.structures]]`, issue 32), lowered: paths resolved, shapes typed, stages
//! defaulted. The files are read and the geometry checked by the geology stage
//! (`geology::objects`), the objects cut into the mesh by `terramesh_faults`.

use std::path::PathBuf;

pub use terramesh_faults::{Profile, STRUCTURE_RESOLUTION as DEFAULT_STRUCTURE_RESOLUTION};

/// What an object is and where its geometry comes from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ObjectSource {
    /// A tunnel: its axis file (CSV `x,y,z`), its profile and its lining's thickness (0:
    /// none).
    Tunnel {
        /// `axis`.
        axis: PathBuf,
        /// `shape` with `diameter` or `width` and `height`.
        profile: Profile,
        /// `lining`, metres.
        lining: f64,
    },
    /// An excavation: its outline file (GeoJSON, WKT or CSV ring), floor and face angle.
    Excavation {
        /// `outline`.
        outline: PathBuf,
        /// `floor`, metres.
        floor: f64,
        /// `face_angle`, degrees from horizontal.
        face_angle: f64,
    },
    /// A structure: its closed surface (STL, OBJ or TSurf) and its material's name.
    Structure {
        /// `solid`.
        solid: PathBuf,
        /// `material`.
        material: String,
    },
}

/// One object, lowered.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectPlan {
    /// Its name.
    pub name: String,
    /// Its geometry.
    pub source: ObjectSource,
    /// Its excavation stage (1 = first; 0 for a structure, never excavated).
    pub stage: u32,
}

impl ObjectPlan {
    /// `tunnel`, `excavation` or `structure`.
    pub fn kind(&self) -> &'static str {
        match self.source {
            ObjectSource::Tunnel { .. } => "tunnel",
            ObjectSource::Excavation { .. } => "excavation",
            ObjectSource::Structure { .. } => "structure",
        }
    }

    /// Its table in the project file: `tunnels`, `excavations` or `structures`.
    pub fn table(&self) -> &'static str {
        match self.source {
            ObjectSource::Tunnel { .. } => "tunnels",
            ObjectSource::Excavation { .. } => "excavations",
            ObjectSource::Structure { .. } => "structures",
        }
    }

    /// The key of one of its settings as the project file writes it:
    /// `geology.tunnels[diversion].diameter`.
    pub fn key(&self, key: &str) -> String {
        format!("geology.{}[{}].{key}", self.table(), self.name)
    }
}
