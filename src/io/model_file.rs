//! Reading model files (TOML, docs/model-format.md).

use std::path::{Path, PathBuf};

use std::sync::Arc;

use crate::analysis::AnalysisSettings;
use crate::model::input::ModelInput;
use crate::model::{Model, ModelErrors};

/// Why a model file could not be turned into a model.
#[derive(Debug, thiserror::Error)]
pub enum ModelFileError {
    /// The file could not be read.
    #[error("{path}: cannot read the file: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not valid TOML or does not follow the schema (unknown
    /// field, wrong type, missing field).
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message, with line and column.
        message: String,
    },
    /// The model is inconsistent (unknown node, zero-length beam...).
    #[error("{}", format_model_errors(path, errors))]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Every problem found.
        errors: ModelErrors,
    },
}

fn format_model_errors(path: &Path, errors: &ModelErrors) -> String {
    errors
        .0
        .iter()
        .map(|e| format!("{}: {e}", path.display()))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Parses model-file text (`path` is only used in messages).
pub fn parse_model(text: &str, path: &Path) -> Result<ModelInput, ModelFileError> {
    toml::from_str(text).map_err(|e| ModelFileError::Parse {
        path: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })
}

/// A model file read and validated: the model and, beside it, the
/// analyses the file asks for, in order.
pub struct ModelFile {
    /// The file as written.
    pub input: ModelInput,
    /// The model.
    pub model: Arc<Model>,
    /// The analyses (`[analysis]`, or each `[[analysis]]` of a sequence).
    pub analyses: Vec<AnalysisSettings>,
}

/// Reads and validates a model file.
pub fn read_model(path: &Path) -> Result<ModelFile, ModelFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| ModelFileError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let input = parse_model(&text, path)?;
    let invalid = |errors| ModelFileError::Invalid {
        path: path.to_path_buf(),
        errors,
    };
    let model = Model::from_input(&input).map_err(invalid)?;
    let analyses = input.analyses().map_err(invalid)?;
    Ok(ModelFile {
        input,
        model: Arc::new(model),
        analyses,
    })
}
