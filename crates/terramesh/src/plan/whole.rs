//! The whole plan of a build ([`Plan`]): every stage's sub-plan, resolved and checked, as
//! the stages take it. A project lowers into it ([`Project::plan`](crate::project::Project::plan));
//! a tiled build stores it in its manifest (JSON), so that a tile runs the stages on it
//! without the project file or its parser.

use serde::{Deserialize, Serialize};

use super::{ExportPlan, GeologyPlan, InterpolationPlan, MeshPlan, SamplingPlan};
use crate::error::Result;
use crate::project::HeightDatum;

/// The resolved plan of a build: one sub-plan per stage, every value typed, every path
/// resolved (against the project file's folder).
///
/// It reads back from its serde form as it was written (a tiled build's manifest holds it
/// as JSON); a sub-plan it does not give takes its default, as a project's missing section
/// does.
///
/// ```
/// use terramesh::plan::Plan;
/// use terramesh::project::{Project, GEOLOGY_TEMPLATE, TEMPLATE};
/// let text = format!("{TEMPLATE}{GEOLOGY_TEMPLATE}");
/// let p = Project::parse("site/terramesh.toml", &text, &["mesh.min_angle=25".into()])?;
/// let plan = p.plan();
/// assert_eq!(plan.mesh.min_angle, 25.0);
/// let json = serde_json::to_string(&plan).expect("a plan is JSON");
/// let again: Plan = serde_json::from_str(&json).expect("and reads back");
/// assert_eq!(again, plan);
/// again.check()?;
/// # Ok::<(), terramesh::Error>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Plan {
    /// The project's `title`, shown in the report and the files that carry one.
    pub title: Option<String>,
    /// `[sampling]`.
    pub sampling: SamplingPlan,
    /// `[mesh]`.
    pub mesh: MeshPlan,
    /// `[interpolation]`.
    pub interpolation: InterpolationPlan,
    /// `[export]`.
    pub export: ExportPlan,
    /// `[geology]` lowered, when the project has one.
    pub geology: Option<GeologyPlan>,
    /// The vertical datum the project names (`[region] vertical_datum`;
    /// [`Project::named_height_datum`](crate::project::Project::named_height_datum)), `None`
    /// when it names none.
    pub vertical_datum: Option<HeightDatum>,
}

impl Plan {
    /// The range checks of every sub-plan, each its own (`SamplingPlan::check`,
    /// [`MeshPlan::check`], [`InterpolationPlan::check`], `ExportPlan::check`,
    /// [`GeologyPlan::check`]), for a plan read from elsewhere than a project file (a
    /// project's are checked as it is parsed). The error names the [`Setting`](crate::Setting).
    ///
    /// ```
    /// let mut plan = terramesh::plan::Plan::default();
    /// plan.check()?;
    /// plan.mesh.min_angle = 40.0;
    /// let e = plan.check().unwrap_err().render(&terramesh::project::key_of);
    /// assert!(e.starts_with("mesh.min_angle '40'"), "{e}");
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn check(&self) -> Result<()> {
        self.sampling.check()?;
        self.mesh.check()?;
        self.interpolation.check()?;
        self.export.check()?;
        if let Some(g) = &self.geology {
            g.check()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::project::Project;

    /// Every example's plan, faults and engineering objects included, reads back from JSON
    /// as it was (a tiled build's manifest holds it so).
    #[test]
    fn every_example_plan_reads_back_from_json() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
        let mut objects = 0;
        let mut faults = 0;
        for name in [
            "haut-barr",
            "kimberlina",
            "shellmound",
            "faulted",
            "structures",
        ] {
            let p = Project::load(&root.join(name).join("terramesh.toml"), &[]).unwrap();
            let plan = p.plan();
            if let Some(g) = &plan.geology {
                objects += g.objects.len();
                faults += g.faults.len();
            }
            let json = serde_json::to_string_pretty(&plan).unwrap();
            let again: Plan = serde_json::from_str(&json).unwrap();
            assert_eq!(again, plan, "{name}: {json}");
            again.check().unwrap();
        }
        assert!(
            objects > 0 && faults > 0,
            "{objects} objects, {faults} faults"
        );
    }
}
