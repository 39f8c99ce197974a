//! `stereolab exercises`: exercise material (the student handout).

use std::path::{Path, PathBuf};

use clap::Subcommand;
use stereolab_core::Result;
use stereolab_grade as grade;

/// What `stereolab exercises` does.
#[derive(Subcommand)]
pub enum ExercisesCommand {
    /// Write the student handout (stubs, tests, assets, the library with the grader; no
    /// solutions) to DIR.
    Export {
        /// Output folder.
        dir: PathBuf,
        /// The stereolab repository (default: . when it has exercises/, else the build's source).
        #[arg(long)]
        root: Option<PathBuf>,
        /// A folder holding the course's copies of the source documents (see docs/sources.md),
        /// copied into the handout's documents/ (they are not redistributable, so the
        /// repository does not ship them).
        #[arg(long)]
        documents: Option<PathBuf>,
    },
}

/// Runs `stereolab exercises`.
///
/// # Errors
/// The handout cannot be read or written.
pub fn run(command: ExercisesCommand) -> Result<()> {
    let ExercisesCommand::Export {
        dir,
        root,
        documents,
    } = command;
    let root = root.unwrap_or_else(|| {
        if Path::new("exercises/ex1_stereo").is_dir() {
            PathBuf::from(".")
        } else {
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        }
    });
    grade::export::export(&root, &dir, documents.as_deref())?;
    outln!("wrote the student handout to {}", dir.display());
    Ok(())
}
