//! Errors of the elevation readers.

/// Errors reading an elevation source. Each names the file and says what to do.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DemError {
    /// The path given as an elevation source does not exist.
    #[error("{file}: does not exist (no such file or directory)")]
    NotFound {
        /// The path as given.
        file: String,
    },
    /// The file could not be opened or read.
    #[error("{file}: {source}")]
    Io {
        /// File name.
        file: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The file's layout or content is not understood or not supported.
    #[error("{file}: {message}")]
    Format {
        /// File name.
        file: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// The file's coordinate reference system is missing or not supported.
    #[error("{file}: {message}")]
    Crs {
        /// File name.
        file: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// A table error from a points CSV.
    #[error(transparent)]
    Table(#[from] crate::table::TableError),
}

/// What a reader says of a file that ends before its data does.
pub(crate) const TRUNCATED: &str = "the file ends before its data does: it is truncated (an \
                                    interrupted download or copy?); get it again";

/// Whether a decoder's message (which may wrap the I/O error in its own words) means the
/// file ended early.
pub(crate) fn is_truncation(message: &str) -> bool {
    message.contains("failed to fill whole buffer") || message.contains("UnexpectedEof")
}

impl DemError {
    /// An I/O error; a missing file is [`DemError::NotFound`], one that ends early says so.
    pub(crate) fn io(file: &std::path::Path, source: std::io::Error) -> DemError {
        if source.kind() == std::io::ErrorKind::NotFound {
            return DemError::not_found(file);
        }
        if source.kind() == std::io::ErrorKind::UnexpectedEof {
            return DemError::format(file, TRUNCATED);
        }
        DemError::Io {
            file: file.display().to_string(),
            source,
        }
    }
    pub(crate) fn not_found(file: &std::path::Path) -> DemError {
        DemError::NotFound {
            file: file.display().to_string(),
        }
    }
    pub(crate) fn format(file: &std::path::Path, message: impl Into<String>) -> DemError {
        DemError::Format {
            file: file.display().to_string(),
            message: message.into(),
        }
    }
    pub(crate) fn crs(file: &std::path::Path, message: impl Into<String>) -> DemError {
        DemError::Crs {
            file: file.display().to_string(),
            message: message.into(),
        }
    }
}
