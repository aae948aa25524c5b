//! Reading numeric CSV tables back (result time series, measured runs): a header row of column
//! names and rows of numbers; empty fields read as NaN.

use std::path::Path;

use vehsim_spec::files::read_input;

use vehsim_core::error::{Error, Result};

/// A numeric table, column-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub columns: Vec<String>,
    pub data: Vec<Vec<f64>>,
}

impl Table {
    /// Parse CSV text; `path` names the source in errors (which give the line number).
    pub fn parse(path: &Path, text: &str) -> Result<Self> {
        let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines.next().ok_or_else(|| Error::input(path, "empty file: expected a header row"))?;
        let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
        let mut data = vec![Vec::new(); columns.len()];
        for (n, line) in lines {
            let fields: Vec<&str> = line.split(',').collect();
            if fields.len() != columns.len() {
                return Err(Error::input(
                    path,
                    format!("line {}: {} fields, the header has {}", n + 1, fields.len(), columns.len()),
                ));
            }
            for (c, f) in fields.iter().enumerate() {
                let f = f.trim();
                let v = if f.is_empty() {
                    f64::NAN
                } else {
                    f.parse::<f64>().map_err(|_| {
                        let (col, val) = (vehsim_core::error::shown(&columns[c]), vehsim_core::error::shown(f));
                        Error::input(path, format!("line {}, column {} {col}: {val} is not a number", n + 1, c + 1))
                    })?
                };
                data[c].push(v);
            }
        }
        Ok(Self { columns, data })
    }

    /// Read and parse a CSV file.
    pub fn read(path: &Path) -> Result<Self> {
        Self::parse(path, &read_input(path)?)
    }

    /// The values of column `name`, if present.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns.iter().position(|c| c == name).map(|i| self.data[i].as_slice())
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.data.first().map_or(0, |c| c.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_numbers_and_empty_fields_and_reports_bad_lines() {
        let p = Path::new("x.csv");
        let t = Table::parse(p, "t_s,v\n0,1.5\n0.1,\n").unwrap();
        assert_eq!(t.rows(), 2);
        assert_eq!(t.column("v").unwrap()[0], 1.5);
        assert!(t.column("v").unwrap()[1].is_nan());
        let e = Table::parse(p, "t_s,v\n0,1\n0.1,abc\n").unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("'v'"), "{e}");
        let e = Table::parse(p, "t_s,v\n0,1,2\n").unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
    }
}
