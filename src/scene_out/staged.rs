//! An output being made from an input document: its JSON, where its binary data will live,
//! and every file beside it, all in memory until [`Staged::write`] writes them (atomically,
//! the scene last, after checking that none of them is an input).
//!
//! | output | the input's buffers and images | new data |
//! |---|---|---|
//! | `.glb` | all in the BIN chunk (`embed`) | appended to the BIN chunk (buffer 0) |
//! | `.gltf`, input `.glb` | BIN chunk -> `<out>.streaklight.bin`; files copied (`side_files`) | appended to `<out>.streaklight.bin` |
//! | `.gltf`, input `.gltf` | files copied beside the output, `data:` URIs kept | a new buffer, `<out>.streaklight.bin` |
//!
//! With [`InputFiles::Reference`] a `.gltf` output refers to the input's files where they are.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use super::document::{self, padded_len, Document, Format};
use super::edit::{len_of, push, root_mut};
use super::side_files::{self, SideFile};
use super::{embed, resources, InputFiles, NewData, ResourceHandling};
use crate::output_file::{self, ensure_not_an_input, WrittenAhead};
use crate::{Error, Result};

/// See the module docs.
pub(crate) struct Staged {
    pub json: Value,
    format: Format,
    /// The BIN chunk of a `.glb` output.
    glb_bin: Option<Vec<u8>>,
    /// For a `.gltf` output of a `.glb` input: buffer 0's bytes, to be `<out>.streaklight.bin`.
    moved_bin0: Option<Vec<u8>>,
    /// Data for a new `<out>.streaklight.bin` buffer of a `.gltf` output.
    new_buffer: Option<(usize, Vec<u8>)>,
    side: Vec<SideFile>,
    other_chunks: Vec<(u32, Vec<u8>)>,
    /// The input and every file it refers to: nothing may be written over them.
    inputs: Vec<PathBuf>,
    data_path: PathBuf,
    data_uri: String,
    pub handling: ResourceHandling,
}

/// The folder a path is in ("." for a bare file name).
pub(crate) fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Reads `input` and prepares writing it as `output` (see the module docs).
pub(crate) fn stage(input: &Path, output: &Path, files: InputFiles) -> Result<Staged> {
    let format = Format::from_output_path(output)?;
    if format == Format::Glb && files == InputFiles::Reference {
        return Err(Error::output(
            output,
            "a .glb output embeds every file it needs; referring to the input's files \
             where they are works only for a .gltf output",
        ));
    }
    let doc = document::read(input)?;
    let input_dir = folder_of(input)
        .canonicalize()
        .map_err(|e| Error::io(input, e))?;
    let folder = folder_of(output);
    let output_dir = folder.canonicalize().map_err(|_| {
        Error::output(
            output,
            format!("the folder {} does not exist", folder.display()),
        )
    })?;
    let stem = output
        .file_stem()
        .and_then(|n| n.to_str())
        .ok_or_else(|| Error::output(output, "the output file name is not valid UTF-8"))?;
    let data_name = side_files::data_name(stem);
    let mut json = doc.json.clone();
    let local = resources::local_resources(&json, &input_dir);
    let mut inputs = vec![input.to_path_buf()];
    inputs.extend(local.iter().map(|r| r.path.clone()));
    // Before any work: the output itself must not be an input (the files beside it are
    // checked when they are known, in `write`).
    ensure_not_an_input(
        output,
        &inputs.iter().map(PathBuf::as_path).collect::<Vec<_>>(),
    )?;
    let mut staged = Staged {
        json: Value::Null,
        format,
        glb_bin: None,
        moved_bin0: None,
        new_buffer: None,
        side: Vec::new(),
        other_chunks: Vec::new(),
        inputs,
        data_path: folder.join(&data_name),
        data_uri: resources::encode_path(&data_name),
        handling: ResourceHandling::default(),
    };
    let h = &mut staged.handling;
    match format {
        Format::Glb => {
            let embedded = embed::embed_all(&mut json, &doc, input, &input_dir)?;
            staged.glb_bin = embedded.bin;
            h.embedded = embedded.embedded;
            h.warnings = embedded.warnings;
            h.dropped_glb_chunks = usize::from(embedded.unused_bin_chunk);
            staged.other_chunks = doc.other_chunks.clone();
        }
        Format::Gltf => {
            staged.moved_bin0 = bin_chunk_buffer(&doc, input)?;
            h.dropped_glb_chunks = doc.other_chunks.len()
                + usize::from(doc.bin_chunk.is_some() && staged.moved_bin0.is_none());
            if staged.moved_bin0.is_some() {
                json["buffers"][0]["uri"] = Value::from(staged.data_uri.clone());
                h.bin_chunk_moved_to = Some(staged.data_path.clone());
            }
            match files {
                InputFiles::Copy => {
                    let (side, copied) = side_files::copy_beside(&mut json, &local, folder, stem)?;
                    staged.side = side;
                    h.copied = copied;
                }
                InputFiles::Reference => {
                    if input_dir != output_dir {
                        h.rewritten_uris =
                            resources::rewrite_uris(&mut json, &local, &output_dir, output)?;
                    }
                    if !local.is_empty() {
                        h.warnings.push(format!(
                            "{} refers to {} file(s) of the input where they are (not copied): \
                             it breaks if they move, and a tool that rewrites it in place may \
                             write into them",
                            output.display(),
                            local.len()
                        ));
                    }
                }
            }
        }
    }
    staged.json = json;
    Ok(staged)
}

impl Staged {
    /// Appends `bytes` to the output's binary data at a 4-byte aligned offset; returns (buffer,
    /// byte offset). Existing buffers keep their index and their bytes.
    pub fn append_data(&mut self, bytes: &[u8], input: &Path) -> Result<(usize, usize)> {
        let (buffer, offset) = if let Some(bin) = self.glb_bin.as_mut().or(self.moved_bin0.as_mut())
        {
            let offset = padded_len(bin.len());
            bin.resize(offset, 0);
            bin.extend_from_slice(bytes);
            let len = bin.len();
            if let Some(b) = self
                .json
                .pointer_mut("/buffers/0")
                .and_then(Value::as_object_mut)
            {
                b.insert("byteLength".into(), Value::from(len));
            }
            self.handling.new_data = NewData::AppendedToBuffer {
                buffer: 0,
                byte_offset: offset,
            };
            (0, offset)
        } else if let Some((buffer, data)) = self.new_buffer.as_mut() {
            let offset = padded_len(data.len());
            data.resize(offset, 0);
            data.extend_from_slice(bytes);
            let len = data.len();
            self.json["buffers"][*buffer]["byteLength"] = Value::from(len);
            (*buffer, offset)
        } else {
            let root = root_mut(&mut self.json, input)?;
            let index = len_of(root, "buffers");
            let glb = self.format == Format::Glb;
            let buffer = if glb {
                json!({ "byteLength": bytes.len(), "name": "streaklight" })
            } else {
                json!({ "byteLength": bytes.len(), "uri": self.data_uri, "name": "streaklight" })
            };
            push(root, "buffers", buffer, input)?;
            if glb {
                self.glb_bin = Some(bytes.to_vec());
            } else {
                self.new_buffer = Some((index, bytes.to_vec()));
            }
            self.handling.new_data = NewData::NewBuffer {
                buffer: index,
                file: (!glb).then(|| self.data_path.clone()),
            };
            (index, 0)
        };
        Ok((buffer, offset))
    }

    /// Takes out the copies of the input's files, to be written ahead
    /// ([`super::CopiesAhead`]).
    pub(super) fn take_side(&mut self) -> Vec<SideFile> {
        std::mem::take(&mut self.side)
    }

    /// Writes the files beside the output, then the output, all together
    /// ([`output_file::Run`]: the output is renamed into place last), the files `ahead`
    /// wrote put in place with them; checks first that none of them is an input or another.
    /// If a write fails, nothing is left written.
    pub fn write(mut self, output: &Path, ahead: Vec<WrittenAhead>) -> Result<ResourceHandling> {
        let mut files = std::mem::take(&mut self.side);
        if let Some(bin) = self.moved_bin0.take() {
            files.push((self.data_path.clone(), bin));
        }
        if let Some((_, bin)) = self.new_buffer.take() {
            files.push((self.data_path.clone(), bin));
        }
        let out_bytes = match self.format {
            Format::Glb => {
                document::glb_bytes(&self.json, self.glb_bin.as_deref(), &self.other_chunks)?
            }
            Format::Gltf => document::gltf_bytes(&self.json)?,
        };
        files.push((output.to_path_buf(), out_bytes));
        let inputs: Vec<&Path> = self.inputs.iter().map(PathBuf::as_path).collect();
        let paths: Vec<&Path> = ahead
            .iter()
            .map(WrittenAhead::path)
            .chain(files.iter().map(|(p, _)| p.as_path()))
            .collect();
        for path in &paths {
            ensure_not_an_input(path, &inputs)?;
        }
        output_file::ensure_distinct(&paths)?;
        let written_ahead: Vec<PathBuf> = ahead.iter().map(|w| w.path().to_path_buf()).collect();
        // All together or nothing: in the caller's run if it opened one, else in our own.
        let run = output_file::Run::begin();
        for written in ahead {
            written.place()?;
        }
        let count = files.len();
        for (k, (path, bytes)) in files.iter().enumerate() {
            if k + 1 == count {
                output_file::write_atomically_last(path, bytes)?;
            } else {
                output_file::write_atomically(path, bytes)?;
            }
        }
        if run.owns() {
            run.commit()?;
        }
        self.handling.files_written = written_ahead
            .into_iter()
            .chain(files.into_iter().map(|(p, _)| p))
            .collect();
        Ok(self.handling)
    }
}

/// The bytes of buffer 0 when it is stored in the input GLB's BIN chunk (its `byteLength`
/// first bytes; the rest of the chunk is padding). Checks the buffers' storage while at it.
pub(crate) fn bin_chunk_buffer(doc: &Document, input: &Path) -> Result<Option<Vec<u8>>> {
    let buffers = doc.json.get("buffers").and_then(Value::as_array);
    let Some(first) = buffers.and_then(|b| b.first()) else {
        return Ok(None);
    };
    if doc.format == Format::Gltf {
        if let Some(i) = buffers
            .into_iter()
            .flatten()
            .position(|b| b.get("uri").is_none() && !embed::is_meshopt_fallback(b))
        {
            return Err(Error::scene(
                input,
                format!(
                    "buffer {i} has no \"uri\"; in a .gltf file every buffer needs one \
                     (but an EXT_meshopt_compression fallback)"
                ),
            ));
        }
        return Ok(None);
    }
    if first.get("uri").is_some() {
        return Ok(None);
    }
    let chunk = doc.bin_chunk.as_deref().ok_or_else(|| {
        Error::scene(
            input,
            "corrupt GLB file: buffer 0 has no \"uri\" but the file has no BIN chunk",
        )
    })?;
    let len = first
        .get("byteLength")
        .and_then(Value::as_u64)
        .and_then(|l| usize::try_from(l).ok())
        .ok_or_else(|| Error::scene(input, "buffer 0 has no valid \"byteLength\""))?;
    let bytes = chunk.get(..len).ok_or_else(|| {
        Error::scene(
            input,
            format!(
                "corrupt GLB file: buffer 0 is {len} bytes but the BIN chunk holds {}",
                chunk.len()
            ),
        )
    })?;
    Ok(Some(bytes.to_vec()))
}

/// What writing `input` as `output` involves, known before any work (see [`super::Plan`]).
pub(crate) fn plan(input: &Path, output: &Path, files: InputFiles) -> Result<super::Plan> {
    let doc = document::read(input)?;
    let own_lights = doc
        .json
        .get("nodes")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter(|n| n.pointer("/extras/streaklight/role") == Some(&json!("light")))
        .map(|n| {
            n.get("name")
                .and_then(Value::as_str)
                .map_or_else(|| "unnamed".into(), crate::names::escaped)
        })
        .collect();
    let input_dir = folder_of(input)
        .canonicalize()
        .map_err(|e| Error::io(input, e))?;
    let local = resources::local_resources(&doc.json, &input_dir);
    let mut reads = vec![input.to_path_buf()];
    reads.extend(local.iter().map(|r| r.path.clone()));
    let mut writes = vec![output.to_path_buf()];
    if Format::from_output_path(output)? == Format::Gltf {
        let folder = folder_of(output);
        let stem = output.file_stem().and_then(|n| n.to_str()).unwrap_or("");
        writes.push(folder.join(side_files::data_name(stem)));
        if files == InputFiles::Copy {
            let mut seen = std::collections::HashSet::new();
            for r in &local {
                if seen.insert(r.path.clone()) {
                    let name = side_files::copy_name(stem, r.kind, r.index, &r.path);
                    writes.push(folder.join(name));
                }
            }
        }
    }
    Ok(super::Plan {
        reads,
        writes,
        own_lights,
    })
}
