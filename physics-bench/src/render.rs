//! `physics-bench render --to DIR FILE.json...`: renders report pages from their JSON
//! alone, without rerunning a bench. Each FILE.json (written by a bench into its --out
//! folder) is copied into DIR as NAME.json beside its page NAME.md (with the charts the page
//! links, NAME-*.svg beside the JSON), and DIR/README.md, the index, is rendered from every
//! report JSON in DIR. `physics-bench render --to
//! docs/reports docs/reports/*.json` renders the stored pages again.

use std::path::{Path, PathBuf};

use super::error::{BenchError, BenchResult};
use super::report::page::{self, Parts};

/// Options of the `render` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct RenderArgs {
    /// Report JSON files, as a bench wrote them (NAME.json in its --out folder).
    #[arg(required = true)]
    pub from: Vec<PathBuf>,
    /// Folder receiving NAME.json, NAME.md and README.md.
    #[arg(long, default_value = "docs/reports")]
    pub to: PathBuf,
}

pub fn run(args: &RenderArgs) -> BenchResult<()> {
    std::fs::create_dir_all(&args.to)
        .map_err(BenchError::io(format!("create {}", args.to.display())))?;
    for from in &args.from {
        let (text, json) = read(from)?;
        let markdown = page::render(&json).map_err(|e| failed(from, e))?;
        let bench = Parts::from_json(&json)
            .map_err(|e| failed(from, e))?
            .run
            .bench;
        let json_to = args.to.join(format!("{bench}.json"));
        if !same_file(from, &json_to) {
            std::fs::write(&json_to, &text)
                .map_err(BenchError::io(format!("write {}", json_to.display())))?;
        }
        copy_charts(from, &bench, &args.to)?;
        let md_to = args.to.join(format!("{bench}.md"));
        std::fs::write(&md_to, markdown)
            .map_err(BenchError::io(format!("write {}", md_to.display())))?;
        println!("wrote {} and {}", json_to.display(), md_to.display());
    }
    let index = args.to.join("README.md");
    std::fs::write(&index, page::index(&reports_in(&args.to)?))
        .map_err(BenchError::io(format!("write {}", index.display())))?;
    println!("wrote {}", index.display());
    Ok(())
}

/// Copies the charts a page links (`NAME-*.svg` beside its JSON) into `to`.
fn copy_charts(json: &Path, bench: &str, to: &Path) -> BenchResult<()> {
    let from = json.parent().unwrap_or(Path::new("."));
    if same_file(from, to) {
        return Ok(());
    }
    let Ok(entries) = std::fs::read_dir(from) else {
        return Ok(());
    };
    let prefix = format!("{bench}-");
    for path in entries.filter_map(|e| e.ok().map(|e| e.path())) {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        if name.starts_with(&prefix) && name.ends_with(".svg") {
            let target = to.join(name);
            std::fs::copy(&path, &target).map_err(BenchError::io(format!(
                "copy {} to {}",
                path.display(),
                target.display()
            )))?;
        }
    }
    Ok(())
}

fn failed(path: &Path, e: String) -> BenchError {
    BenchError::Failed(format!("{}: {e}", path.display()))
}

fn read(path: &Path) -> BenchResult<(String, serde_json::Value)> {
    let text = std::fs::read_to_string(path)
        .map_err(BenchError::io(format!("read {}", path.display())))?;
    let json = serde_json::from_str(&text).map_err(|e| failed(path, e.to_string()))?;
    Ok((text, json))
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Every report in `dir` (the JSON files with a `run`), by name.
fn reports_in(dir: &Path) -> BenchResult<Vec<Parts>> {
    let entries =
        std::fs::read_dir(dir).map_err(BenchError::io(format!("list {}", dir.display())))?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    paths.sort();
    let mut reports = Vec::new();
    for path in paths {
        if let Ok(parts) = Parts::from_json(&read(&path)?.1) {
            reports.push(parts);
        }
    }
    Ok(reports)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::{self, Goal};

    #[test]
    fn render_puts_the_page_its_json_its_charts_and_the_index_into_the_folder() {
        let root = std::env::temp_dir().join(format!("render-{}", std::process::id()));
        let (out, docs) = (root.join("out"), root.join("docs"));
        #[derive(serde::Serialize)]
        struct Tiny {
            goals: Vec<Goal>,
        }
        let tiny = Tiny {
            goals: vec![Goal::new("tiny goal", "1", Some(false))],
        };
        let (json, md) = report::write(&out, "tiny", &tiny, "# Tiny bench\n\nbody\n").unwrap();
        std::fs::write(out.join("tiny-chart.svg"), "<svg/>").unwrap();
        run(&RenderArgs {
            from: vec![json.clone()],
            to: docs.clone(),
        })
        .unwrap();
        let page = std::fs::read_to_string(docs.join("tiny.md")).unwrap();
        assert_eq!(page, std::fs::read_to_string(&md).unwrap());
        assert_eq!(
            std::fs::read_to_string(docs.join("tiny.json")).unwrap(),
            std::fs::read_to_string(&json).unwrap()
        );
        assert!(docs.join("tiny-chart.svg").is_file());
        let index = std::fs::read_to_string(docs.join("README.md")).unwrap();
        assert!(index.contains("[Tiny bench](tiny.md)"), "{index}");
        assert!(index.contains("**1 not met**"), "{index}");
        // Rendering the folder's own JSON again leaves the page as it was.
        run(&RenderArgs {
            from: vec![docs.join("tiny.json")],
            to: docs.clone(),
        })
        .unwrap();
        assert_eq!(std::fs::read_to_string(docs.join("tiny.md")).unwrap(), page);
        let _ = std::fs::remove_dir_all(&root);
    }
}
