#pragma once
// Placeholder: arrives with the service issue.
