"""`engine serve` (issue 32): the shop floor's side of the engine. Programs delivered to the
controls on request (an FTP server, a request folder on a network share), each rendered from the
released version, proved and recorded at the moment it is asked for; and a web view of gears,
jobs, programs, releases and machines. Above release/ (it shows impacts and releases), below cli/."""
