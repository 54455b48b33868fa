//! `convert`: a pbrt-v4 scene file to the equivalent RON scene
//! ([`rust_v::scene::pbrt::convert`]); the importer's warnings are printed one
//! line each, as `render` prints them.

use rust_v::error::{Error, Result, show_path};
use rust_v::io::{check_aliasing, check_output};
use rust_v::scene::pbrt::{convert, is_pbrt};

use super::args::ConvertArgs;
use super::console::{say, warn};

pub fn convert_command(args: ConvertArgs) -> Result<()> {
    if !is_pbrt(&args.scene) {
        return Err(Error::Settings(format!(
            "convert reads pbrt-v4 scenes: expected a name ending in .pbrt, found {}",
            show_path(&args.scene)
        )));
    }
    if !args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("ron")) {
        return Err(Error::Settings(format!("output {}: expected a name ending in .ron", show_path(&args.output))));
    }
    check_output(&args.output, "output")?;
    check_aliasing(&[("scene", args.scene.as_path())], &[("output", args.output.as_path())])?;
    let (warnings, files) = convert(&args.scene, &args.output, args.strict)?;
    for w in &warnings {
        warn(format_args!("{w}"));
    }
    say(format_args!(
        "wrote {}{}",
        show_path(&args.output),
        match files.len() {
            0 => String::new(),
            n => format!(" and {n} file{} beside it (meshes, media grids, maps)", if n == 1 { "" } else { "s" }),
        }
    ));
    Ok(())
}
